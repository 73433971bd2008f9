// cadgen studio: the parameter form, generated from GET /api/schema for the design's kind.
// One collapsible group per table; each field shows its unit, default, bounds and description,
// and the server's own message when a value does not validate. Numbers are typed as text, so
// whatever the designer typed ("abc", "1e400") reaches the validator, which names the problem.
import {element} from "./dom.js";
import {getPath} from "./params.js";

/** Fields not edited in the form (with the reason shown in their place). */
const NOT_IN_FORM = {
  "trajectory.points": "Drag the points on the loop plot (double-click the loop to add one, " +
    "right-click or Alt-click a point to remove it).",
};
/** Top-level identity fields: changing them would make another design, not edit this one. */
const READ_ONLY = new Set(["mechanism"]);

function formatNumber(value) {
  return typeof value === "number" ? String(value) : value;
}

function boundsText(field) {
  const parts = [];
  if (field.minimum !== null && field.minimum !== undefined)
    parts.push(`${field.exclusive_minimum ? ">" : ">="} ${field.minimum}`);
  if (field.maximum !== null && field.maximum !== undefined)
    parts.push(`${field.exclusive_maximum ? "<" : "<="} ${field.maximum}`);
  return parts.join(", ");
}

function defaultText(field) {
  if (field.default === null || field.default === undefined) return "";
  return Array.isArray(field.default) ? field.default.join(", ") : String(field.default);
}

/** The field's value as the input shows it. */
function displayValue(field, value) {
  if (value === undefined || value === null) return "";
  if (field.type === "array" || field.type === "point") {
    if (Array.isArray(value) && value.every((v) => typeof v !== "object")) return value.join(", ");
    return JSON.stringify(value);
  }
  if (typeof value === "object") return JSON.stringify(value);
  return formatNumber(value);
}

/** The JSON value for the input's text; text that does not parse is sent as typed. */
function parseValue(field, text) {
  const trimmed = text.trim();
  if (trimmed === "") return undefined;   // left empty: the schema default applies
  switch (field.type) {
    case "number":
    case "integer": {
      const number = Number(trimmed);
      return trimmed !== "" && Number.isFinite(number) ? number : trimmed;
    }
    case "array":
    case "point": {
      if (trimmed.startsWith("[")) {
        try { return JSON.parse(trimmed); } catch (error) { return trimmed; }
      }
      return trimmed.split(/[,\s]+/).filter(Boolean).map((part) => {
        const number = Number(part);
        return Number.isFinite(number) ? number : part;
      });
    }
    case "string":
    case "enum":
      return trimmed;
    default:
      try { return JSON.parse(trimmed); } catch (error) { return trimmed; }
  }
}

export class ParameterForm {
  /**
   * @param {HTMLElement} root  where the groups go
   * @param {object} kindSchema  `schema.kinds[kind]`: {tables: [...]}
   * @param {(path: string, value: any) => void} onChange
   */
  constructor(root, kindSchema, onChange) {
    this.root = root;
    this.onChange = onChange;
    this.fields = new Map();   // path -> {field, input, message, group}
    this.general = element("ul", {class: "problems-general", "aria-live": "polite"});
    root.replaceChildren(this.general);
    kindSchema.tables.forEach((table, index) => root.appendChild(this.group(table, index)));
  }

  group(table, index) {
    const details = element("details", {class: "group", "data-table": table.name});
    details.open = index < 4;   // the first tables (the design's core) open, the rest folded
    const summary = element("summary", {}, table.title || table.name || "design");
    if (table.name) summary.appendChild(element("code", {class: "table-name"}, `[${table.name}]`));
    details.appendChild(summary);
    if (table.description) details.appendChild(element("p", {class: "group-note"}, table.description));
    table.fields.forEach((field) => details.appendChild(this.row(field, details)));
    return details;
  }

  row(field, group) {
    const id = `field-${field.path.replace(/[^A-Za-z0-9_-]/g, "-")}`;
    const row = element("div", {class: "field", "data-path": field.path});
    const label = element("label", {for: id, title: field.description || ""});
    const key = element("span", {class: "field-key"});
    field.key.split("_").forEach((part, i) => {   // long keys break after an underscore only
      if (i > 0) key.append("_", document.createElement("wbr"));
      key.append(part);
    });
    label.appendChild(key);
    if (field.unit) label.appendChild(element("span", {class: "field-unit"}, field.unit));
    row.appendChild(label);
    let input;
    if (NOT_IN_FORM[field.path]) {
      input = null;
      row.appendChild(element("p", {class: "field-note"}, NOT_IN_FORM[field.path]));
    } else if (field.type === "boolean") {
      input = element("input", {id, type: "checkbox"});
      input.addEventListener("change", () => this.onChange(field.path, input.checked));
    } else if (Array.isArray(field.enum) && field.type !== "number" && field.type !== "array") {
      input = element("select", {id});
      if (!field.required) input.appendChild(element("option", {value: ""}, `(default ${defaultText(field)})`));
      field.enum.forEach((choice) => input.appendChild(element("option", {value: String(choice)}, String(choice))));
      input.addEventListener("change", () => this.onChange(field.path, parseValue(field, input.value)));
    } else {
      const numeric = field.type === "number" || field.type === "integer";
      input = element("input", {id, type: "text", spellcheck: "false", autocomplete: "off",
                                 inputmode: numeric ? "decimal" : null,
                                 placeholder: defaultText(field) ? `default ${defaultText(field)}` : null});
      input.addEventListener("input", () => this.onChange(field.path, parseValue(field, input.value)));
      if (Array.isArray(field.enum) && field.type === "number") {
        // a number or one of the named choices (gears.split_exponent): suggest the names
        const list = element("datalist", {id: `${id}-choices`});
        field.enum.forEach((choice) => list.appendChild(element("option", {value: String(choice)})));
        row.appendChild(list);
        input.setAttribute("list", list.id);
      }
    }
    if (input) {
      input.setAttribute("aria-describedby", `${id}-help`);
      if (READ_ONLY.has(field.path)) input.disabled = true;
      row.appendChild(input);
    }
    const help = element("small", {id: `${id}-help`, class: "field-help"});
    const bits = [field.description, boundsText(field), defaultText(field) && `default ${defaultText(field)}`];
    help.textContent = bits.filter(Boolean).join(" · ");
    row.appendChild(help);
    const message = element("p", {class: "field-problem", role: "alert", hidden: true});
    row.appendChild(message);
    this.fields.set(field.path, {field, input, message, group, row});
    return row;
  }

  /** Shows `params` in the inputs (after load, undo, redo); leaves the focused input alone
   * when it already holds that value, so typing is never disturbed. */
  setValues(params) {
    for (const [path, {field, input}] of this.fields) {
      if (!input) continue;
      const value = getPath(params, path);
      if (field.type === "boolean") {
        input.checked = value === undefined ? Boolean(field.default) : Boolean(value);
        continue;
      }
      const text = displayValue(field, value);
      if (document.activeElement === input && parseValue(field, input.value) === value) continue;
      if (input.value !== text) input.value = text;
    }
  }

  /** Every problem beside its field (its group opened); those no field owns, listed on top. */
  showProblems(problems) {
    for (const {message, row} of this.fields.values()) {
      message.hidden = true;
      message.textContent = "";
      row.classList.remove("invalid");
    }
    this.general.replaceChildren();
    for (const problem of problems || []) {
      const entry = this.fields.get(problem.path) || this.owner(problem.path);
      const text = problem.stage ? `${problem.message} (stage ${problem.stage})` : problem.message;
      if (entry) {
        entry.message.textContent = entry.message.textContent ? `${entry.message.textContent} ${text}` : text;
        entry.message.hidden = false;
        entry.row.classList.add("invalid");
        entry.group.open = true;
      } else {
        this.general.appendChild(element("li", {}, problem.path ? `${problem.path}: ${text}` : text));
      }
    }
  }

  /** The field a deeper path belongs to ("trajectory.points.3" -> "trajectory.points"). */
  owner(path) {
    if (!path) return null;
    const keys = path.split(".");
    for (let n = keys.length - 1; n > 0; n -= 1) {
      const entry = this.fields.get(keys.slice(0, n).join("."));
      if (entry) return entry;
    }
    return null;
  }
}
