// cadgen studio: hand-written SVG for the geometric views (tip paths, the loop, pitch curves).
// Data are mm with y up; the SVG draws (x, -y), and its viewBox with preserveAspectRatio "meet"
// keeps one mm the same length on both axes (equal aspect, as a drawing must be).

export const NS = "http://www.w3.org/2000/svg";
/** Screen size of one marker/text unit, px (grid labels are 2.6 units: about 10 px). */
const UNIT_PX = 3.8;

export function svgElement(tag, attributes = {}, parent = null) {
  const el = document.createElementNS(NS, tag);
  for (const [name, value] of Object.entries(attributes)) {
    if (value !== null && value !== undefined) el.setAttribute(name, value);
  }
  if (parent) parent.appendChild(el);
  return el;
}

/** "x0,-y0 x1,-y1 ..." for a polyline from columnar arrays. */
export function pointsText(xs, ys) {
  const out = new Array(xs.length);
  for (let i = 0; i < xs.length; i += 1) out[i] = `${xs[i]},${-ys[i]}`;
  return out.join(" ");
}

/** [xmin, ymin, xmax, ymax] round columnar {x, y} sets and [x, y] points (y up). */
export function bounds(sets, points = []) {
  let box = [Infinity, Infinity, -Infinity, -Infinity];
  const add = (x, y) => {
    if (!Number.isFinite(x) || !Number.isFinite(y)) return;
    box = [Math.min(box[0], x), Math.min(box[1], y), Math.max(box[2], x), Math.max(box[3], y)];
  };
  for (const set of sets) if (set) set.x.forEach((x, i) => add(x, set.y[i]));
  for (const point of points) if (point) add(point[0], point[1]);
  return box;
}

function niceStep(span) {
  const raw = span / 6, power = 10 ** Math.floor(Math.log10(raw));
  for (const factor of [1, 2, 5, 10]) if (raw <= factor * power) return factor * power;
  return 10 * power;
}

/** An equal-aspect SVG view of mm data: a grid with labels, then whatever `draw` adds. */
export class GeometryView {
  constructor(container, label) {
    this.svg = svgElement("svg", {class: "geometry", role: "img", "aria-label": label,
                                  preserveAspectRatio: "xMidYMid meet"});
    container.appendChild(this.svg);
    this.unit = 1;
  }

  /** Clears the view, frames `box` (mm, y up) with a margin, draws the grid; returns the <g>
   * to draw in. `this.unit` is then 1 % of the larger span: the size of markers and text. */
  reset(box) {
    const [xmin, ymin, xmax, ymax] = box.every(Number.isFinite) ? box : [-100, -100, 100, 100];
    const span = Math.max(xmax - xmin, ymax - ymin, 1);
    const pad = 0.07 * span;
    this.box = [xmin - pad, ymin - pad, xmax + pad, ymax + pad];
    // markers and text are sized in mm; make one unit about UNIT_PX on screen at the scale the
    // view will draw at (a wide, flat view would otherwise get huge labels), 1 % of the span
    // when the view is not laid out yet
    const rect = this.svg.getBoundingClientRect();
    const pixelsPerMm = Math.min(rect.width / (this.box[2] - this.box[0]), rect.height / (this.box[3] - this.box[1]));
    this.unit = rect.width > 0 && rect.height > 0 ? UNIT_PX / pixelsPerMm : span / 100;
    const [left, bottom, right, top] = this.box;
    this.svg.setAttribute("viewBox", `${left} ${-top} ${right - left} ${top - bottom}`);
    this.svg.replaceChildren();
    const grid = svgElement("g", {class: "gridlines"}, this.svg);
    const step = niceStep(span);
    const text = {class: "grid-label", "font-size": 2.6 * this.unit};
    for (let x = Math.ceil(left / step) * step; x <= right; x += step) {
      svgElement("line", {x1: x, x2: x, y1: -top, y2: -bottom}, grid);
      svgElement("text", {...text, x: x + 0.6 * this.unit, y: -bottom - 0.8 * this.unit}, grid)
        .textContent = `${Math.round(x)}`;
    }
    for (let y = Math.ceil(bottom / step) * step; y <= top; y += step) {
      svgElement("line", {x1: left, x2: right, y1: -y, y2: -y}, grid);
      svgElement("text", {...text, x: left + 0.6 * this.unit, y: -y - 0.6 * this.unit}, grid)
        .textContent = `${Math.round(y)}`;
    }
    svgElement("text", {...text, class: "grid-label unit", x: right - 6 * this.unit,
                        y: -bottom - 0.8 * this.unit}).textContent = "mm";
    return svgElement("g", {class: "drawing"}, this.svg);
  }

  polyline(parent, xs, ys, cls) {
    return svgElement("polyline", {class: cls, points: pointsText(xs, ys)}, parent);
  }

  marker(parent, point, cls, label = "") {
    const group = svgElement("g", {class: `marker ${cls}`}, parent);
    svgElement("circle", {cx: point[0], cy: -point[1], r: 1.1 * this.unit}, group);
    if (label) {   // entry to the left, exit to the right, the lowest point below: they crowd
      const u = this.unit;
      const [dx, dy, anchor] = /\bentry\b/.test(cls) ? [-2.6 * u, -1.2 * u, "end"]
        : /\blowest\b/.test(cls) ? [0, 4.2 * u, "middle"] : [2.6 * u, -1.2 * u, "start"];
      svgElement("text", {x: point[0] + dx, y: -point[1] + dy, "text-anchor": anchor,
                          "font-size": 2.8 * u}, group).textContent = label;
    }
    return group;
  }

  /** A horizontal line across the view at height `y` (the soil surface), earth shaded below. */
  soil(parent, y, cls = "soil") {
    if (y === null || y === undefined || !this.box) return;
    const [left, bottom, right] = this.box;
    if (y > bottom) {
      svgElement("rect", {class: `${cls}-fill`, x: left, width: right - left, y: -y,
                          height: y - bottom}, parent);
    }
    svgElement("line", {class: cls, x1: left, x2: right, y1: -y, y2: -y}, parent);
  }

  /** Client (screen) coordinates -> data mm (y up), for dragging. */
  toData(clientX, clientY) {
    const point = this.svg.createSVGPoint();
    point.x = clientX;
    point.y = clientY;
    const local = point.matrixTransform(this.svg.getScreenCTM().inverse());
    return [local.x, -local.y];
  }
}
