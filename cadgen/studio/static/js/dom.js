// cadgen studio: the two DOM helpers every view uses.

/** An element with attributes (null, undefined and false ones left out) and text. */
export function element(tag, attributes = {}, text = "") {
  const el = document.createElement(tag);
  for (const [name, value] of Object.entries(attributes)) {
    if (value !== null && value !== undefined && value !== false) el.setAttribute(name, value);
  }
  if (text) el.textContent = text;
  return el;
}

/** A titled panel in the results grid; returns its body, where the view goes. */
export function panel(grid, id, title, note = "") {
  const section = element("section", {class: "panel", id, "aria-labelledby": `${id}-title`});
  section.appendChild(element("h2", {id: `${id}-title`}, title));
  if (note) section.appendChild(element("p", {class: "panel-note"}, note));
  const body = element("div", {class: "panel-body"});
  section.appendChild(body);
  grid.appendChild(section);
  return body;
}
