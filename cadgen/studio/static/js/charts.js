// cadgen studio: plots against carrier angle, drawn by the vendored uPlot (window.uPlot, a
// classic script). The events (catching, entry, lowest, exit) are vertical lines drawn in
// uPlot's draw hook; a pinned design's curves are extra, faint series on the same x.

const EVENT_COLOURS = {catching: "#2a9d4b", entry: "#8b5a2b", lowest: "#b02a2a", exit: "#6a3fa0"};

/** `values` sampled at `xFrom`, linearly interpolated onto `xTo` (a pinned design may have been
 * sampled differently). */
function resample(xFrom, values, xTo) {
  if (xFrom.length === xTo.length && xFrom.every((x, i) => x === xTo[i])) return values;
  const out = new Array(xTo.length);
  let j = 0;
  for (let i = 0; i < xTo.length; i += 1) {
    const x = xTo[i];
    while (j < xFrom.length - 2 && xFrom[j + 1] < x) j += 1;
    const x0 = xFrom[j], x1 = xFrom[j + 1];
    const t = x1 === x0 ? 0 : Math.min(1, Math.max(0, (x - x0) / (x1 - x0)));
    out[i] = values[j] + t * (values[j + 1] - values[j]);
  }
  return out;
}

export class AngleChart {
  /**
   * @param {HTMLElement} container
   * @param {object} options  {yLabel, height, xLabel}
   */
  constructor(container, {yLabel, xLabel = "carrier angle from catching, deg", height = 210}) {
    this.container = container;
    this.yLabel = yLabel;
    this.xLabel = xLabel;
    this.height = height;
    this.plot = null;
    this.signature = "";
    this.events = {};
    if (window.ResizeObserver) {
      new ResizeObserver(() => this.resize()).observe(container);
    }
  }

  width() {
    return Math.max(240, Math.floor(this.container.clientWidth || 400));
  }

  resize() {
    if (this.plot && Math.abs(this.plot.width - this.width()) > 2)
      this.plot.setSize({width: this.width(), height: this.height});
  }

  drawEvents(u) {
    const context = u.ctx, {top, height} = u.bbox;
    context.save();
    context.lineWidth = Math.max(1, window.devicePixelRatio || 1);
    context.setLineDash([5, 4]);
    context.font = `${Math.round(11 * (window.devicePixelRatio || 1))}px sans-serif`;
    const pixel = window.devicePixelRatio || 1;
    const sorted = Object.entries(this.events).filter(([, deg]) => Number.isFinite(deg)).sort((a, b) => a[1] - b[1]);
    let previous = -Infinity, row = 0;
    for (const [name, deg] of sorted) {
      const x = Math.round(u.valToPos(deg, "x", true));
      context.strokeStyle = context.fillStyle = EVENT_COLOURS[name] || "#555";
      context.beginPath();
      context.moveTo(x, top);
      context.lineTo(x, top + height);
      context.stroke();
      row = x - previous < 48 * pixel ? row + 1 : 0;   // close events: labels one under another
      previous = x;
      context.fillText(name, x + 3, top + (12 + 12 * row) * pixel);
    }
    context.restore();
  }

  /**
   * @param {object} data  {x: [...], series: [{label, values, colour, dash}], events: {name: deg},
   *                        pinned: {x, series: [{label, values}]} | null}
   */
  update({x, series, events = {}, pinned = null}) {
    this.events = events || {};
    const pinnedSeries = pinned ? pinned.series.filter((s) => s.values && s.values.length) : [];
    const signature = JSON.stringify([series.map((s) => s.label), pinnedSeries.map((s) => s.label)]);
    const data = [x, ...series.map((s) => s.values),
                  ...pinnedSeries.map((s) => resample(pinned.x, s.values, x))];
    if (this.plot && signature === this.signature) {
      this.plot.setData(data);
      return;
    }
    if (this.plot) this.plot.destroy();
    this.signature = signature;
    const options = {
      width: this.width(), height: this.height,
      scales: {x: {time: false, range: [0, 360]}},
      axes: [{label: this.xLabel, values: (u, ticks) => ticks.map((t) => `${t}`)},
             {label: this.yLabel, size: 56}],
      legend: {live: true},
      cursor: {drag: {x: false, y: false}},
      series: [{label: "angle, deg"},
               ...series.map((s) => ({label: s.label, stroke: s.colour, width: 1.8,
                                      dash: s.dash || undefined, points: {show: false}})),
               ...pinnedSeries.map((s) => ({label: `pinned: ${s.label}`, stroke: "rgba(90,100,115,0.45)",
                                            width: 1.5, dash: [6, 4], points: {show: false}}))],
      hooks: {draw: [(u) => this.drawEvents(u)]},
    };
    this.plot = new window.uPlot(options, data, this.container);
  }
}
