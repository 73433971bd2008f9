// cadgen studio: the pricking mechanism's views. The loop with its type-value points, which the
// designer drags (pointer events on the SVG circles), adds (double-click on the loop) and removes
// (right-click or Alt-click); on release the inverse design re-runs through the page's evaluation.
// Then: a, l, the ratio, the four pitch curves (concave stretches red), the findings, the field.
import {panel} from "./dom.js";
import {formatValue} from "./metrics.js";
import {GeometryView, bounds, svgElement} from "./svg.js";

const INCLINATION_COLOURS = ["#1f77b4", "#2a9d4b", "#6a3fa0", "#c0392b"];

/** Points are written to the file to 0.1 mm, as the bundled designs give them. */
const roundTenth = (value) => Math.round(value * 10) / 10;

function nearestIndex(xs, ys, point) {
  let best = 0, bestDistance = Infinity;
  for (let i = 0; i < xs.length; i += 1) {
    const d = (xs[i] - point[0]) ** 2 + (ys[i] - point[1]) ** 2;
    if (d < bestDistance) { best = i; bestDistance = d; }
  }
  return best;
}

/** Where a point picked on the loop goes in the point list: between the two type-value points
 * whose stretch of the loop holds it (the loop passes through the points in their order). */
export function insertionIndex(loop, points, picked) {
  const n = loop.x.length;
  const at = points.map((p) => nearestIndex(loop.x, loop.y, p));
  const pickedAt = nearestIndex(loop.x, loop.y, picked);
  const ahead = (from, to) => ((to - from) % n + n) % n;   // loop samples from `from` on to `to`
  for (let i = 0; i < points.length; i += 1) {
    const next = (i + 1) % points.length;
    if (ahead(at[i], pickedAt) < ahead(at[i], at[next])) return i + 1;
  }
  return points.length;
}

export class PrickingViews {
  /** @param {(points: number[][]) => void} onPointsChange  called on release, add and remove */
  constructor(grid, onPointsChange) {
    this.onPointsChange = onPointsChange;
    const loopBody = panel(grid, "panel-loop", "Needle-tip loop and its type-value points",
      "Drag a point; double-click the loop to add one; right-click or Alt-click a point to remove it.");
    loopBody.parentElement.classList.add("wide");
    this.loop = new GeometryView(loopBody, "needle-tip loop with draggable type-value points");
    this.loop.svg.classList.add("loop-view");
    this.summary = panel(grid, "panel-design", "Inverse design");
    this.curves = panel(grid, "panel-pitch", "Pitch curves",
      "Each gear in its own frame, centred on its axis; concave stretches in red (no cutter fits them).");
    this.field = panel(grid, "panel-field", "In the field, per inclination",
      "The tip over the ground in the hole's vertical plane (two turns), the soil surface of each " +
      "inclination dashed in its colour; the needle's angles at entry and exit.");
    this.field.parentElement.classList.add("wide");
    this.fieldView = new GeometryView(this.field, "absolute tip paths per inclination");
    this.fieldView.svg.classList.add("field-view");
    this.fieldLegend = Object.assign(document.createElement("ul"), {className: "plot-legend"});
    this.fieldTable = document.createElement("div");
    this.field.append(this.fieldLegend, this.fieldTable);
    this.findings = panel(grid, "panel-findings", "Findings");
    this.findings.parentElement.classList.add("wide");
    this.answer = null;
    this.points = [];
    this.dragging = null;
    this.loop.svg.addEventListener("dblclick", (event) => this.addPoint(event));
  }

  /** Draws a new answer; `points` are the parameters' points (they may differ from the answer's
   * when the last drag gave an invalid design: the picture stays, the points go where dropped). */
  update(answer, points, pinned) {
    if (this.dragging) { this.deferred = [answer, points, pinned]; return; }
    this.answer = answer;
    this.pinned = pinned;
    this.points = points.map((p) => [...p]);
    this.drawLoop();
    this.drawSummary(answer.report, pinned && pinned.report);
    this.drawCurves(answer.pitch_curves || [], (pinned && pinned.pitch_curves) || []);
    this.drawFieldPaths(answer.field || []);
    this.drawField(answer.report && answer.report.field, answer.report && answer.report.findings);
  }

  /** Shows `points` (after an undo, or an invalid answer) over the last good loop. */
  setPoints(points) {
    this.points = points.map((p) => [...p]);
    if (this.answer && !this.dragging) this.drawLoop();
  }

  drawLoop() {
    const answer = this.answer, view = this.loop;
    const pinnedLoop = this.pinned && this.pinned.loop;
    const box = bounds([answer.loop, pinnedLoop], [...this.points, answer.centre]);
    const g = view.reset(box);
    if (pinnedLoop) view.polyline(g, [...pinnedLoop.x, pinnedLoop.x[0]], [...pinnedLoop.y, pinnedLoop.y[0]], "pinned");
    const closed = [[...answer.loop.x, answer.loop.x[0]], [...answer.loop.y, answer.loop.y[0]]];
    this.loopLine = view.polyline(g, closed[0], closed[1], "loop");
    view.polyline(g, closed[0], closed[1], "loop-hit");   // a wide invisible stroke to double-click
    if (answer.centre) view.marker(g, answer.centre, "centre", "O");
    this.polygon = view.polyline(g, [], [], "control-polygon");
    this.handles = this.points.map((point, index) => {
      const handle = svgElement("circle", {class: "tv-point", cx: point[0], cy: -point[1],
                                           r: 1.6 * view.unit, tabindex: "0", "data-index": index,
                                           role: "button", "aria-label": `type-value point Q${index + 1}`}, g);
      svgElement("title", {}, handle).textContent = `Q${index + 1} (${point[0]}, ${point[1]}) mm`;
      svgElement("text", {class: "tv-label", x: point[0] + 2 * view.unit, y: -point[1] + view.unit,
                          "font-size": 3 * view.unit}, g).textContent = `Q${index + 1}`;
      this.bindHandle(handle, index);
      return handle;
    });
  }

  bindHandle(handle, index) {
    handle.addEventListener("pointerdown", (event) => {
      if (event.button !== 0 || event.altKey) return;
      event.preventDefault();
      handle.setPointerCapture(event.pointerId);
      this.dragging = {index, moved: false};
      handle.classList.add("dragging");
    });
    handle.addEventListener("pointermove", (event) => {
      if (!this.dragging || this.dragging.index !== index) return;
      const [x, y] = this.loop.toData(event.clientX, event.clientY);
      this.points[index] = [roundTenth(x), roundTenth(y)];
      this.dragging.moved = true;
      handle.setAttribute("cx", this.points[index][0]);
      handle.setAttribute("cy", -this.points[index][1]);
      this.loop.svg.classList.add("editing");
    });
    const release = () => {
      if (!this.dragging || this.dragging.index !== index) return;
      const moved = this.dragging.moved;
      this.dragging = null;
      handle.classList.remove("dragging");
      this.loop.svg.classList.remove("editing");
      if (this.deferred) {
        const [answer, , pinned] = this.deferred;
        this.deferred = null;
        this.answer = answer;
        this.pinned = pinned;
      }
      if (moved) this.onPointsChange(this.points.map((p) => [...p]));
      else this.drawLoop();
    };
    handle.addEventListener("pointerup", release);
    handle.addEventListener("pointercancel", release);
    handle.addEventListener("click", (event) => { if (event.altKey) this.removePoint(event, index); });
    handle.addEventListener("contextmenu", (event) => this.removePoint(event, index));
  }

  removePoint(event, index) {
    event.preventDefault();
    const points = this.points.filter((_, i) => i !== index);
    this.onPointsChange(points);
  }

  addPoint(event) {
    if (!this.answer || event.target.classList.contains("tv-point")) return;
    const picked = this.loop.toData(event.clientX, event.clientY);
    const loop = this.answer.loop;
    const onLoop = nearestIndex(loop.x, loop.y, picked);
    const distance = Math.hypot(loop.x[onLoop] - picked[0], loop.y[onLoop] - picked[1]);
    if (distance > 4 * this.loop.unit) return;   // a double-click away from the loop adds nothing
    const at = insertionIndex(loop, this.points, picked);
    const points = this.points.map((p) => [...p]);
    points.splice(at, 0, [roundTenth(loop.x[onLoop]), roundTenth(loop.y[onLoop])]);
    this.onPointsChange(points);
  }

  drawSummary(report, pinnedReport) {
    if (!report) return;
    const linkage = report.linkage || {}, gears = report.gears || {};
    const rows = [
      ["pricking-a", "centre distance a", linkage.centre_distance_a_mm, "mm", (r) => r.linkage.centre_distance_a_mm],
      ["pricking-l", "tip reach l", linkage.tip_reach_l_mm, "mm", (r) => r.linkage.tip_reach_l_mm],
      ["pricking-l2", "needle l2", linkage.needle_l2_mm, "mm", (r) => r.linkage.needle_l2_mm],
      ["pricking-ratio-min", "total ratio i, min", gears.total_ratio_min, "", (r) => r.gears.total_ratio_min],
      ["pricking-ratio-max", "total ratio i, max", gears.total_ratio_max, "", (r) => r.gears.total_ratio_max],
      ["pricking-w", "split exponent w", gears.split_exponent_w, "", (r) => r.gears.split_exponent_w],
      ["pricking-scale", "scale of the loop", gears.scale, "", (r) => r.gears.scale],
    ];
    const table = document.createElement("table");
    table.className = "design-summary";
    const head = table.createTHead().insertRow();
    for (const name of ["", "value", ...(pinnedReport ? ["pinned"] : [])]) {
      const th = document.createElement("th");
      th.textContent = name;
      head.appendChild(th);
    }
    for (const [id, label, value, unit, pick] of rows) {
      const row = table.insertRow();
      row.insertCell().textContent = label;
      const cell = row.insertCell();
      cell.id = id;
      cell.className = "value";
      cell.dataset.value = value;
      cell.textContent = `${formatValue(value, unit ? 2 : 4)}${unit ? ` ${unit}` : ""}`;
      if (pinnedReport) {
        let other = null;
        try { other = pick(pinnedReport); } catch (error) { other = null; }
        row.insertCell().textContent = formatValue(other, unit ? 2 : 4);
      }
    }
    const teeth = gears.teeth ? `teeth ${gears.teeth.join(" / ")}; modules ${(gears.modules_mm || []).map((m) => formatValue(m, 3)).join(" / ")} mm` : "";
    const verdict = document.createElement("p");
    verdict.className = report.verified ? "verdict pass" : "verdict fail";
    verdict.textContent = `${report.verified ? "verified: the forward run retraces the loop" : "not verified"}` +
      (report.verification ? ` (deviation ${formatValue(report.verification.forward_deviation_mm, 4)} mm)` : "") +
      (teeth ? `; ${teeth}` : "");
    this.summary.replaceChildren(table, verdict);
  }

  drawCurves(curves, pinnedCurves) {
    const row = document.createElement("div");
    row.className = "pitch-row";
    for (const curve of curves) {
      const figure = document.createElement("figure");
      figure.className = curve.convex ? "pitch convex" : "pitch concave";
      const view = new GeometryView(figure, `pitch curve ${curve.name}`);
      const pinnedCurve = pinnedCurves.find((c) => c.name === curve.name);
      const g = view.reset(bounds([curve, pinnedCurve], [[0, 0]]));
      if (pinnedCurve) view.polyline(g, [...pinnedCurve.x, pinnedCurve.x[0]], [...pinnedCurve.y, pinnedCurve.y[0]], "pinned");
      const xs = [...curve.x, curve.x[0]], ys = [...curve.y, curve.y[0]];
      view.polyline(g, xs, ys, "pitch-curve");
      for (const [start, end] of curve.concave || []) {
        const wrap = end < start;
        const indices = [];
        for (let i = start; wrap ? i < curve.x.length : i <= end; i += 1) indices.push(i);
        if (wrap) for (let i = 0; i <= end; i += 1) indices.push(i);
        view.polyline(g, indices.map((i) => curve.x[i]), indices.map((i) => curve.y[i]), "concave");
      }
      view.marker(g, [0, 0], "axis");
      const caption = document.createElement("figcaption");
      caption.textContent = `${curve.name} (stage ${curve.stage}, ${curve.role})${curve.convex ? "" : ": concave"}`;
      figure.appendChild(caption);
      row.appendChild(figure);
    }
    this.curves.replaceChildren(row);
  }

  drawFieldPaths(field) {
    const view = this.fieldView;
    const box = bounds(field.map((f) => f.tip));
    for (const f of field) box[1] = Math.min(box[1], f.surface - 10);
    const g = view.reset(box);
    const legend = [];
    field.forEach((f, index) => {
      const colour = INCLINATION_COLOURS[index % INCLINATION_COLOURS.length];
      const [left, , right] = view.box;
      svgElement("line", {class: "surface", x1: left, x2: right, y1: -f.surface, y2: -f.surface,
                          style: `stroke:${colour}`}, g);
      view.polyline(g, f.tip.x, f.tip.y, "field-path").style.stroke = colour;
      const item = document.createElement("li");
      item.innerHTML = `<span class="swatch" style="background:${colour}"></span>${f.inclination_deg} deg: ` +
        `entry ${formatValue(f.entry_angle_deg, 1)} deg, exit ${formatValue(f.exit_angle_deg, 1)} deg`;
      legend.push(item);
    });
    this.fieldLegend.replaceChildren(...legend);
  }

  drawField(field, findings) {
    const parts = [];
    if (field && field.per_inclination) {
      const table = document.createElement("table");
      table.className = "field-table";
      const head = table.createTHead().insertRow();
      for (const name of ["inclination", "entry angle", "exit angle", "hole mouth", "in soil"]) {
        const th = document.createElement("th");
        th.textContent = name;
        head.appendChild(th);
      }
      for (const r of field.per_inclination) {
        const row = table.insertRow();
        for (const [value, unit] of [[r.inclination_deg, "deg"], [r.needle_entry_angle_deg, "deg"],
                                     [r.needle_exit_angle_deg, "deg"], [r.hole_mouth_mm, "mm"],
                                     [r.time_in_soil_deg, "deg"]]) {
          row.insertCell().textContent = `${formatValue(value, 1)} ${unit}`;
        }
      }
      parts.push(table);
    }
    this.fieldTable.replaceChildren(...parts);
    const list = document.createElement("ul");
    list.className = "findings";
    for (const finding of findings || []) {
      const item = document.createElement("li");
      item.textContent = `${finding.message} (${finding.code}${finding.path ? `, ${finding.path}` : ""})`;
      list.appendChild(item);
    }
    if (!(findings || []).length) list.appendChild(Object.assign(document.createElement("li"), {textContent: "no findings"}));
    this.findings.replaceChildren(list);
  }
}
