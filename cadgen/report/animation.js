// cadgen report: plays the mechanism's precomputed poses (cadgen/report/animation.py) in an SVG.
// Nothing is computed here: each frame sets the points of the moving shapes to that pose's.
(function () {
  "use strict";
  var NS = "http://www.w3.org/2000/svg";
  var reduced = window.matchMedia && window.matchMedia("(prefers-reduced-motion: reduce)").matches;
  window.cadgenAnimations = window.cadgenAnimations || [];

  function pairs(flat) {
    var out = [];
    for (var i = 0; i + 1 < flat.length; i += 2) out.push(flat[i] + "," + flat[i + 1]);
    return out.join(" ");
  }

  function shape(svg, type, cls) {
    var el = document.createElementNS(NS, type);
    el.setAttribute("class", cls);
    svg.appendChild(el);
    return el;
  }

  function init(root) {
    var data = JSON.parse(root.querySelector("script.anim-data").textContent);
    var svg = root.querySelector("svg.anim-stage");
    var view = data.view, n = data.angles.length;
    if (data.soil !== null && data.soil !== undefined) {
      var soil = shape(svg, "rect", "soil-fill");
      soil.setAttribute("x", view[0]); soil.setAttribute("width", view[2]);
      soil.setAttribute("y", data.soil);
      soil.setAttribute("height", Math.max(0, view[1] + view[3] - data.soil));
      var line = shape(svg, "line", "soil");
      line.setAttribute("x1", view[0]); line.setAttribute("x2", view[0] + view[2]);
      line.setAttribute("y1", data.soil); line.setAttribute("y2", data.soil);
    }
    // the machine's parts under everything else: each outline once, moved by its pose
    var layer = data.parts || {outlines: {}, instances: []};
    var parts = layer.instances.map(function (p) {
      var el = shape(svg, "polygon", p.cls);
      el.setAttribute("points", pairs(layer.outlines[p.part]));
      return {el: el, frames: p.frames};
    });
    data.static.forEach(function (s) { shape(svg, s.type, s.cls).setAttribute("points", pairs(s.points)); });
    var trails = data.trails.map(function (t) { return {el: shape(svg, "polyline", t.cls), points: t.points}; });
    var moving = data.moving.map(function (m) { return {el: shape(svg, m.type, m.cls), m: m}; });
    if (data.kind === "planting") {   // the carrier's axis O, the frame's origin
      shape(svg, "circle", "origin").setAttribute("r", view[2] / 150);
    }
    var play = root.querySelector(".anim-play"), slider = root.querySelector(".anim-slider");
    var label = root.querySelector(".anim-angle");
    var state = {root: root, frame: 0, frames: n, playing: !reduced, drawn: 0};
    window.cadgenAnimations.push(state);

    function draw(k) {
      state.frame = k;
      moving.forEach(function (item) {
        var f = item.m.frames[k];
        if (item.m.type === "circle") {
          item.el.setAttribute("cx", f[0]); item.el.setAttribute("cy", f[1]);
          item.el.setAttribute("r", item.m.r);
        } else {
          item.el.setAttribute("points", pairs(f));
        }
      });
      parts.forEach(function (p) {
        var i = 3 * k;
        p.el.setAttribute("transform", "translate(" + p.frames[i] + "," + p.frames[i + 1] +
                          ") rotate(" + p.frames[i + 2] + ")");
      });
      trails.forEach(function (t) { t.el.setAttribute("points", pairs(t.points.slice(0, 2 * (k + 1)))); });
      slider.value = k;
      label.textContent = data.angle_label + ": " + data.angles[k].toFixed(0) + " deg";
      root.setAttribute("data-frame", k);
      state.drawn += 1;
    }

    var start = null, startFrame = 0;
    function tick(now) {
      if (!state.playing) return;
      if (start === null) { start = now; startFrame = state.frame; }
      var k = (startFrame + Math.floor((now - start) / 1000 * n / data.seconds)) % n;
      if (k !== state.frame) draw(k);
      requestAnimationFrame(tick);
    }
    function setPlaying(on) {
      state.playing = on;
      play.textContent = on ? "Pause" : "Play";
      root.setAttribute("data-playing", on ? "true" : "false");
      if (on) { start = null; requestAnimationFrame(tick); }
    }
    play.addEventListener("click", function () { setPlaying(!state.playing); });
    slider.addEventListener("input", function () { setPlaying(false); draw(parseInt(slider.value, 10)); });
    draw(0);
    setPlaying(state.playing);
  }

  document.querySelectorAll(".cadgen-animation").forEach(function (root) {
    try { init(root); } catch (error) {
      root.setAttribute("data-error", String(error));
      if (window.console) console.error("cadgen animation:", error);
    }
  });
})();
