// cadgen studio: the animation player. It plays the data format of the report's animation
// (cadgen/report/animation.py: poses, angles, view, soil, static, moving, trails, legend; y
// already flipped for SVG) and the studio's extensions: housings, pitch curves and duckbill
// (more moving shapes; a rigid one is its shape once, "local", and a [x, y, deg] placement per
// pose), advance_mm_per_turn (absolute motion at a spacing) and events (marked on the timeline).
// Nothing is computed here but the shift of absolute motion: x + advance * k / poses.
import {svgElement} from "./svg.js";

const SPEEDS = [0.25, 0.5, 1, 2, 4];
const reducedMotion = window.matchMedia && window.matchMedia("(prefers-reduced-motion: reduce)").matches;

function pairs(flat, shift = 0) {
  const out = [];
  for (let i = 0; i + 1 < flat.length; i += 2) out.push(`${flat[i] + shift},${flat[i + 1]}`);
  return out.join(" ");
}

/** Each pose's point of a trail shifted by the advance up to that pose (the absolute frame). */
function advancedPairs(flat, advancePerPose, count) {
  const out = [];
  for (let j = 0; j < count && 2 * j + 1 < flat.length; j += 1)
    out.push(`${flat[2 * j] + advancePerPose * j},${flat[2 * j + 1]}`);
  return out.join(" ");
}

function control(tag, attributes, parent, text = "") {
  const el = document.createElement(tag);
  for (const [name, value] of Object.entries(attributes)) el.setAttribute(name, value);
  if (text) el.textContent = text;
  parent.appendChild(el);
  return el;
}

export class AnimationPlayer {
  constructor(container) {
    this.root = control("div", {class: "player", "data-frame": "0", "data-playing": "false"}, container);
    const options = control("div", {class: "player-options"}, this.root);
    const modeLabel = control("label", {}, options, "motion ");
    this.mode = control("select", {"aria-label": "relative or absolute motion"}, modeLabel);
    control("option", {value: "relative"}, this.mode, "relative to the machine");
    control("option", {value: "absolute"}, this.mode, "absolute, over the ground");
    this.spacingLabel = control("label", {}, options, "spacing ");
    this.spacing = control("select", {"aria-label": "plant spacing for absolute motion"}, this.spacingLabel);
    this.variantLabel = control("label", {}, options, "inclination ");
    this.variant = control("select", {"aria-label": "inclination"}, this.variantLabel);
    this.stage = svgElement("svg", {class: "anim-stage", role: "img", "aria-label": "mechanism animation",
                                    preserveAspectRatio: "xMidYMid meet"}, this.root);
    const controls = control("div", {class: "anim-controls"}, this.root);
    this.play = control("button", {type: "button", class: "anim-play"}, controls, "Play");
    const track = control("div", {class: "anim-track"}, controls);
    this.slider = control("input", {type: "range", class: "anim-slider", min: "0", max: "0", value: "0",
                                    step: "1", "aria-label": "pose"}, track);
    this.timeline = control("div", {class: "anim-timeline", "aria-label": "events"}, track);
    const speedLabel = control("label", {class: "anim-speed"}, controls, "speed ");
    this.speed = control("select", {"aria-label": "playback speed"}, speedLabel);
    for (const s of SPEEDS) control("option", {value: String(s)}, this.speed, `${s}x`);
    this.speed.value = "1";
    this.label = control("span", {class: "anim-angle"}, controls);
    this.legend = control("ul", {class: "anim-legend"}, this.root);
    this.note = control("p", {class: "anim-note"}, this.root);

    this.frame = 0;
    this.playing = false;
    this.data = null;
    this.variants = [];
    this.drawn = 0;
    this.play.addEventListener("click", () => this.setPlaying(!this.playing));
    this.slider.addEventListener("input", () => { this.setPlaying(false); this.draw(Number(this.slider.value)); });
    this.mode.addEventListener("change", () => this.build());
    this.spacing.addEventListener("change", () => this.build());
    this.variant.addEventListener("change", () => this.build());
    this.tick = this.tick.bind(this);
  }

  /**
   * Shows new animation data, keeping the pose, mode and play state.
   * @param {object|object[]} data  one animation, or one per variant (the pricking inclinations)
   * @param {object} options  {variantNames: [...], pinned: data of a pinned design or null}
   */
  load(data, {variantNames = null, pinned = null} = {}) {
    this.variants = Array.isArray(data) ? data : [data];
    this.pinnedVariants = pinned ? (Array.isArray(pinned) ? pinned : [pinned]) : [];
    const names = variantNames || this.variants.map((_, i) => `${i + 1}`);
    const keep = this.variant.value;
    this.variant.replaceChildren(...names.map((name, i) => {
      const option = document.createElement("option");
      option.value = String(i);
      option.textContent = name;
      return option;
    }));
    this.variant.value = keep && Number(keep) < names.length ? keep : "0";
    this.variantLabel.hidden = this.variants.length < 2;
    const advance = this.variants[0] && this.variants[0].advance_mm_per_turn || {};
    const keepSpacing = this.spacing.value;
    this.spacing.replaceChildren(...Object.keys(advance).map((spacing) => {
      const option = document.createElement("option");
      option.value = spacing;
      option.textContent = `${spacing} mm`;
      return option;
    }));
    if (keepSpacing in advance) this.spacing.value = keepSpacing;
    const hasAbsolute = Object.keys(advance).length > 0;
    this.mode.disabled = !hasAbsolute;
    this.mode.parentElement.hidden = !hasAbsolute;
    if (!hasAbsolute) this.mode.value = "relative";
    this.build();
    if (this.firstLoad === undefined) {
      this.firstLoad = false;
      this.setPlaying(!reducedMotion);
    }
  }

  /** Creates the shapes of the chosen variant and mode (once per load, not per frame). */
  build() {
    const data = this.data = this.variants[Number(this.variant.value) || 0];
    if (!data) return;
    const poses = data.poses || data.angles.length;
    const absolute = this.mode.value === "absolute" && data.advance_mm_per_turn;
    const advance = absolute ? Number(data.advance_mm_per_turn[this.spacing.value] || 0) : 0;
    this.advancePerPose = advance / poses;
    this.spacingLabel.hidden = !absolute;
    const [x, y, width, height] = data.view;
    this.stage.setAttribute("viewBox", `${x} ${y} ${width + Math.abs(advance)} ${height}`);
    this.stage.replaceChildren();
    const view = [x, y, width + Math.abs(advance), height];
    if (data.soil !== null && data.soil !== undefined) {
      svgElement("rect", {class: "soil-fill", x: view[0], width: view[2], y: data.soil,
                          height: Math.max(0, view[1] + view[3] - data.soil)}, this.stage);
      svgElement("line", {class: "soil", x1: view[0], x2: view[0] + view[2], y1: data.soil, y2: data.soil}, this.stage);
    }
    const pinned = this.pinnedVariants[Number(this.variant.value) || 0];
    if (pinned && !absolute) {
      for (const s of pinned.static || []) svgElement("polyline", {class: "pinned", points: pairs(s.points)}, this.stage);
    }
    for (const s of data.static || []) {
      if (absolute && /\bpath\b/.test(s.cls)) continue;   // the relative tip path means nothing here
      svgElement(s.type || "polyline", {class: s.cls, points: pairs(s.points)}, this.stage);
    }
    if (absolute) {   // the whole absolute tip path of each arm, faint, under its trail
      for (const t of data.trails) {
        svgElement("polyline", {class: `${t.cls} full`, points: advancedPairs(t.points, this.advancePerPose, poses)}, this.stage);
      }
    }
    const layers = [...(data.housings || []), ...(data.pitch_curves || []), ...(data.moving || []),
                    ...(data.duckbill || [])].filter((m) => m && Array.isArray(m.frames));
    this.trails = data.trails.map((t) => ({el: svgElement("polyline", {class: t.cls}, this.stage), points: t.points}));
    this.moving = layers.map((m) => {
      const el = svgElement(m.type || "polygon", {class: m.cls}, this.stage);
      if (m.local) el.setAttribute("points", pairs(m.local));   // a rigid shape: drawn once, moved per pose
      return {el, m};
    });
    if (data.kind === "planting") svgElement("circle", {class: "origin", r: width / 150}, this.stage);
    this.origin = this.stage.querySelector(".origin");
    this.slider.max = String(data.angles.length - 1);
    this.drawTimeline(data);
    this.drawLegend(data);
    this.note.textContent = data.duckbill_note || "";
    this.note.hidden = !data.duckbill_note;
    this.draw(Math.min(this.frame, data.angles.length - 1));
  }

  drawTimeline(data) {
    const last = Math.max(1, data.angles.length - 1);
    let previous = -Infinity, row = 0, rows = 1;
    this.timeline.replaceChildren(...(data.events || []).map((event) => {
      const at = (100 * event.frame) / last;
      row = at - previous < 9 ? (row + 1) % 3 : 0;   // close events: labels on staggered rows
      previous = at;
      rows = Math.max(rows, row + 1);
      const mark = document.createElement("button");
      mark.type = "button";
      mark.className = `anim-event ${event.name}`;
      mark.style.left = `${at}%`;
      mark.style.top = `${4 + 17 * row}px`;
      mark.style.setProperty("--rise", `${4 + 17 * row}px`);
      mark.textContent = event.name;
      mark.title = `${event.name} at ${Number(event.deg).toFixed(1)} deg: go to this pose`;
      mark.addEventListener("click", () => { this.setPlaying(false); this.draw(event.frame); });
      return mark;
    }));
    this.timeline.style.height = `${9 + 17 * rows}px`;
    this.timeline.hidden = !(data.events || []).length;
  }

  drawLegend(data) {
    this.legend.replaceChildren(...(data.legend || []).map(([cls, text]) => {
      const item = document.createElement("li");
      const swatch = svgElement("svg", {width: 26, height: 10, "aria-hidden": "true"}, item);
      svgElement("line", {class: cls, x1: 1, y1: 5, x2: 25, y2: 5}, swatch);
      item.appendChild(document.createTextNode(text));
      return item;
    }));
  }

  draw(k) {
    const data = this.data;
    this.frame = k;
    const shift = this.advancePerPose * k;
    for (const {el, m} of this.moving) {
      const f = m.frames[k];
      if (!f) continue;
      if (m.local) {   // rigid: [x, y, rotation in deg] (SVG's sense), see the studio's animation.py
        el.setAttribute("transform", `translate(${f[0] + shift},${f[1]}) rotate(${f[2]})`);
      } else if (m.type === "circle") {
        el.setAttribute("cx", f[0] + shift);
        el.setAttribute("cy", f[1]);
        el.setAttribute("r", m.r);
      } else {
        el.setAttribute("points", pairs(f, shift));
      }
    }
    if (this.origin) this.origin.setAttribute("cx", shift);
    for (const t of this.trails) {
      t.el.setAttribute("points", this.advancePerPose
        ? advancedPairs(t.points, this.advancePerPose, k + 1) : pairs(t.points.slice(0, 2 * (k + 1))));
    }
    this.slider.value = String(k);
    this.label.textContent = `${data.angle_label}: ${data.angles[k].toFixed(0)} deg`;
    this.root.dataset.frame = String(k);
    this.drawn += 1;
  }

  setPlaying(on) {
    this.playing = on;
    this.play.textContent = on ? "Pause" : "Play";
    this.root.dataset.playing = on ? "true" : "false";
    if (on) {
      this.start = null;
      requestAnimationFrame(this.tick);
    }
  }

  tick(now) {
    if (!this.playing || !this.data) return;
    const n = this.data.angles.length;
    if (this.start === null) {
      this.start = now;
      this.startFrame = this.frame;
      this.startSpeed = Number(this.speed.value);
    }
    if (Number(this.speed.value) !== this.startSpeed) {   // speed changed: restart the clock here
      this.start = now;
      this.startFrame = this.frame;
      this.startSpeed = Number(this.speed.value);
    }
    const elapsed = (now - this.start) / 1000;
    const k = (this.startFrame + Math.floor((elapsed * n * this.startSpeed) / this.data.seconds)) % n;
    if (k !== this.frame) this.draw(k);
    requestAnimationFrame(this.tick);
  }
}
