// cadgen studio: the metrics table (target, value, margin, pass/fail), the cells that changed
// since the previous answer highlighted, and a pinned design's values as an extra column.

/** A metric's identity across answers: its key and, for per-spacing metrics, the spacing. */
export function metricId(metric) {
  return `${metric.key}@${metric.spacing_mm ?? ""}`;
}

export function formatValue(value, digits = 2) {
  if (value === null || value === undefined) return "n/a";
  if (typeof value !== "number") return String(value);
  if (!Number.isFinite(value)) return String(value);
  return value.toFixed(digits);
}

/**
 * The margin from the target's text, used only when the server gives none: positive means the
 * value passes by that much (in the metric's unit). Targets read "> 500", "< 10", "0-30", "= 1".
 */
export function marginFromTarget(value, target) {
  if (typeof value !== "number" || typeof target !== "string") return null;
  const text = target.trim();
  let match = text.match(/^(>=|>|≥)\s*(-?[\d.]+(?:e-?\d+)?)/i);
  if (match) return value - Number(match[2]);
  match = text.match(/^(<=|<|≤)\s*(-?[\d.]+(?:e-?\d+)?)/i);
  if (match) return Number(match[2]) - value;
  match = text.match(/^(-?[\d.]+)\s*(?:-|–|\.\.)\s*(-?[\d.]+)$/);
  if (match) return Math.min(value - Number(match[1]), Number(match[2]) - value);
  match = text.match(/^=\s*(-?[\d.]+)/);
  if (match) return -Math.abs(value - Number(match[1]));
  return null;
}

/** The server's margin entry for a metric ({margin, margin_normalised}), if it gave one. */
function serverMargin(answer, metric, index) {
  const margins = answer.margins;
  if (Array.isArray(margins)) {
    const found = margins.find((m) => m.key === metric.key &&
      (m.spacing_mm ?? null) === (metric.spacing_mm ?? null)) || margins[index];
    if (found && found.margin !== undefined) return found;
  }
  return undefined;
}

export class MetricsTable {
  constructor(container) {
    this.container = container;
    this.previous = new Map();   // metricId -> formatted value shown last time
  }

  /** Draws `answer.metrics`; `pinned` (an earlier answer) adds its column. */
  update(answer, pinned = null) {
    const metrics = answer.metrics || [];
    const pinnedValues = new Map((pinned && pinned.metrics || []).map((m) => [metricId(m), m]));
    const table = document.createElement("table");
    table.className = "metrics";
    const head = table.createTHead().insertRow();
    const columns = ["metric", "target", "value", "margin", "result"];
    if (pinned) columns.push("pinned");
    for (const name of columns) {
      const th = document.createElement("th");
      th.scope = "col";
      th.textContent = name;
      head.appendChild(th);
    }
    const body = table.createTBody();
    const shown = new Map();
    metrics.forEach((metric, index) => {
      const id = metricId(metric);
      const row = body.insertRow();
      row.dataset.key = metric.key;
      row.dataset.spacing = metric.spacing_mm ?? "";
      row.className = metric.passed ? "pass" : "fail";
      const unit = metric.unit ? ` ${metric.unit}` : "";
      const spacing = metric.spacing_mm !== null && metric.spacing_mm !== undefined
        ? ` (S = ${metric.spacing_mm} mm)` : "";
      const cells = {};
      cells.metric = `${metric.label}${spacing}`;
      cells.target = `${metric.target}${unit}`;
      cells.value = formatValue(metric.value);
      const given = serverMargin(answer, metric, index);
      const margin = given ? given.margin : marginFromTarget(metric.value, metric.target);
      const normalised = given ? given.margin_normalised : null;
      cells.margin = margin === null || margin === undefined ? "n/a" : formatValue(margin);
      cells.result = metric.verdict || (metric.passed ? "pass" : "fail");
      if (pinned) {
        const other = pinnedValues.get(id);
        cells.pinned = other ? formatValue(other.value) : "—";
      }
      for (const name of columns) {
        const cell = row.insertCell();
        cell.className = name;
        cell.textContent = cells[name];
        if (name === "value") {
          cell.dataset.value = metric.value;
          if (this.previous.has(id) && this.previous.get(id) !== cells.value) {
            cell.classList.add("changed");
            cell.title = `was ${this.previous.get(id)}`;
          }
        }
        if (name === "margin" && typeof margin === "number") {
          cell.dataset.value = margin;
          if (typeof normalised === "number") cell.title = `${(100 * normalised).toFixed(0)} % of the target's bound`;
        }
        if (name === "result") cell.classList.add(metric.passed ? "pass" : "fail");
      }
      shown.set(id, cells.value);
    });
    this.previous = shown;
    this.container.replaceChildren(table);
  }
}
