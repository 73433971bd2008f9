// cadgen studio: the planting mechanism's views: the relative tip path with both arms at the
// catching pose and the soil line, the absolute paths at each plant spacing (entry, lowest and
// exit marked), attitude and tip speed against carrier angle, and the metrics table. A pinned
// answer is drawn first, faint, under the current one.
import {AngleChart} from "./charts.js";
import {panel} from "./dom.js";
import {MetricsTable} from "./metrics.js";
import {GeometryView, bounds, svgElement} from "./svg.js";

const SPACING_COLOURS = ["#1f77b4", "#2a9d4b", "#6a3fa0", "#c0392b", "#8c6d1f"];
const ARM_CLASSES = {1: "arm1", 2: "arm2"};
const CHAIN = ["O", "C", "E", "P1", "N"];

export class PlantingViews {
  constructor(grid) {
    this.metrics = new MetricsTable(panel(grid, "panel-metrics", "Metrics against the targets",
      "Changed values are highlighted; margin > 0 passes by that much."));
    this.relative = new GeometryView(panel(grid, "panel-relative", "Relative tip path",
      "Tip N of both arms over one carrier turn, the arms at the catching pose, the soil line."),
      "relative tip path with both arms at catching");
    const absolute = panel(grid, "panel-absolute", "Absolute paths per plant spacing",
      "The tip over the ground at each spacing; entry, lowest point and exit marked.");
    this.absolute = new GeometryView(absolute, "absolute tip paths at each plant spacing");
    this.spacingLegend = Object.assign(document.createElement("ul"), {className: "plot-legend"});
    absolute.appendChild(this.spacingLegend);
    // both plots against carrier angle in one panel, one above the other: their x axes line up
    const charts = panel(grid, "panel-angle", "Against carrier angle",
      "Planter attitude and tip speed (relative, and absolute per spacing); the events dashed.");
    const attitude = Object.assign(document.createElement("div"), {className: "chart", id: "chart-attitude"});
    const speed = Object.assign(document.createElement("div"), {className: "chart", id: "chart-speed"});
    charts.append(attitude, speed);
    this.attitude = new AngleChart(attitude, {yLabel: "attitude, deg", height: 190});
    this.speed = new AngleChart(speed, {yLabel: "tip speed, mm/s", height: 190});
  }

  update(answer, pinned) {
    this.metrics.update(answer, pinned);
    this.drawRelative(answer.relative, pinned && pinned.relative);
    this.drawAbsolute(answer.absolute, pinned && pinned.absolute);
    this.drawCharts(answer.series, pinned && pinned.series);
  }

  drawRelative(relative, pinned) {
    if (!relative) return;
    const armPoints = relative.arms.flatMap((arm) => CHAIN.map((k) => arm.points[k]).filter(Boolean));
    const circlePoints = (relative.circles || []).flatMap((c) => [[c.x - c.r, c.y - c.r], [c.x + c.r, c.y + c.r]]);
    const box = bounds([...relative.paths, ...(pinned ? pinned.paths : [])], [...armPoints, ...circlePoints]);
    if (relative.soil !== null && relative.soil !== undefined) box[1] = Math.min(box[1], relative.soil - 20);
    const view = this.relative, g = view.reset(box);
    view.soil(g, relative.soil);
    if (pinned) pinned.paths.forEach((p) => view.polyline(g, p.x, p.y, "pinned"));
    for (const circle of relative.circles || []) {
      svgElement("circle", {class: "housing", cx: circle.x, cy: -circle.y, r: circle.r}, g)
        .appendChild(svgElement("title")).textContent = circle.name;
    }
    relative.paths.forEach((p) => view.polyline(g, p.x, p.y, `path ${ARM_CLASSES[p.arm] || ""}`));
    for (const arm of relative.arms) {
      const chain = CHAIN.map((k) => arm.points[k]).filter(Boolean);
      view.polyline(g, chain.map((p) => p[0]), chain.map((p) => p[1]), `arm ${ARM_CLASSES[arm.arm] || ""}`);
      for (const [name, point] of Object.entries(arm.points)) {
        svgElement("circle", {class: "joint", cx: point[0], cy: -point[1], r: 0.7 * view.unit}, g)
          .appendChild(svgElement("title")).textContent = `arm ${arm.arm}: ${name}`;
      }
    }
    for (const event of relative.events || []) view.marker(g, [event.x, event.y], `event ${event.name}`, event.name);
  }

  drawAbsolute(absolute, pinned) {
    if (!absolute) return;
    const spacings = absolute.spacings || [];
    const box = bounds([...spacings, ...(pinned ? pinned.spacings : [])]);
    if (absolute.soil !== null && absolute.soil !== undefined) box[1] = Math.min(box[1], absolute.soil - 20);
    const view = this.absolute, g = view.reset(box);
    view.soil(g, absolute.soil);
    if (pinned) pinned.spacings.forEach((s) => view.polyline(g, s.x, s.y, "pinned"));
    const legend = [];
    spacings.forEach((spacing, index) => {
      const colour = SPACING_COLOURS[index % SPACING_COLOURS.length];
      view.polyline(g, spacing.x, spacing.y, "spacing-path").style.stroke = colour;
      for (const name of ["entry", "lowest", "exit"]) {
        if (spacing[name]) view.marker(g, spacing[name], `event ${name}`, index === 0 ? name : "");
      }
      const item = document.createElement("li");
      item.innerHTML = `<span class="swatch" style="background:${colour}"></span>S = ${spacing.spacing} mm`;
      legend.push(item);
    });
    if (pinned) {
      const item = document.createElement("li");
      item.innerHTML = '<span class="swatch pinned"></span>pinned design';
      legend.push(item);
    }
    this.spacingLegend.replaceChildren(...legend);
  }

  drawCharts(series, pinned) {
    if (!series) return;
    const events = series.events_deg || {};
    this.attitude.update({
      x: series.angle_deg, events,
      series: [{label: "attitude", values: series.attitude_deg, colour: "#1f77b4"}],
      pinned: pinned ? {x: pinned.angle_deg, series: [{label: "attitude", values: pinned.attitude_deg}]} : null,
    });
    const absolute = Object.entries(series.speed_absolute_mm_s || {});
    this.speed.update({
      x: series.angle_deg, events,
      series: [{label: "relative", values: series.speed_relative_mm_s, colour: "#333"},
               ...absolute.map(([spacing, values], i) => ({label: `absolute S=${spacing}`, values,
                 colour: SPACING_COLOURS[i % SPACING_COLOURS.length], dash: [4, 3]}))],
      pinned: pinned ? {x: pinned.angle_deg,
                        series: [{label: "relative", values: pinned.speed_relative_mm_s}]} : null,
    });
  }
}

