// cadgen studio: the page. It loads the design and the schema, builds the form, and keeps one
// loop going: an edit (a field, a drag, undo/redo) changes the parameters, which are recorded in
// the history and evaluated (debounced, stale answers dropped); a valid answer redraws every
// view, an invalid one shows the server's problems and leaves the last good picture, greyed.
import {getJson, hasToken} from "./api.js";
import {BuildPanel} from "./build.js";
import {panel} from "./dom.js";
import {Evaluator} from "./evaluator.js";
import {ParameterForm} from "./form.js";
import {History} from "./history.js";
import {clone, getPath, setPath} from "./params.js";
import {AnimationPlayer} from "./player.js";
import {PlantingViews} from "./planting.js";
import {PrickingViews} from "./pricking.js";
import {SaveControls} from "./save.js";

const $ = (id) => document.getElementById(id);

const studio = window.cadgenStudio = {
  state: "loading", params: null, answer: null, pinned: null, evaluations: 0, problems: [],
};

function setStatus(text, kind) {
  const status = $("eval-status");
  status.textContent = text;
  status.dataset.kind = kind;
}

function showNotices(warnings) {
  const list = $("notices");
  list.replaceChildren(...(warnings || []).map((warning) => {
    const item = document.createElement("li");
    item.textContent = `warning: ${warning.message}${warning.stage ? ` (stage ${warning.stage})` : ""}`;
    return item;
  }));
}

function redraw() {
  const answer = studio.answer;
  if (!answer) return;
  const pinned = studio.pinned && studio.pinned.answer;
  if (studio.kind === "pricking") {
    studio.views.update(answer, getPath(studio.params, "trajectory.points") || answer.points, pinned);
    const names = (answer.field || []).map((f) => `${f.inclination_deg} deg`);
    studio.player.load(answer.animation, {variantNames: names, pinned: pinned && pinned.animation});
  } else {
    studio.views.update(answer, pinned);
    studio.player.load(answer.animation, {pinned: pinned && pinned.animation});
  }
}

function onResult(answer, params) {
  studio.answer = answer;
  studio.answerParams = params;
  studio.evaluations += 1;
  studio.problems = [];
  studio.form.showProblems([]);
  showNotices(answer.warnings);
  $("results").classList.remove("stale");
  const server = Number.isFinite(answer.elapsed_ms) ? `${answer.elapsed_ms.toFixed(0)} ms` : "";
  setStatus(`${server} (round trip ${answer.round_trip_ms.toFixed(0)} ms)`, "ok");
  redraw();
  studio.state = "ready";
  document.body.dataset.evaluations = String(studio.evaluations);
}

function onProblems(error, params) {
  studio.problems = error.problems;
  studio.form.showProblems(error.problems);
  $("results").classList.add("stale");
  const count = error.problems.length;
  setStatus(`invalid: ${count} problem${count === 1 ? "" : "s"}; showing the last valid design`, "error");
  if (studio.kind === "pricking") studio.views.setPoints(getPath(params, "trajectory.points") || []);
  studio.state = "invalid";
}

function onFailure(error) {
  $("results").classList.add("stale");
  setStatus(`evaluation failed: ${error.message}`, "error");
  studio.state = "error";
}

/** An edit from `source` (a field path, or "drag"): record it, evaluate it. */
function edited(source, {immediately = false} = {}) {
  studio.history.record(studio.params, source);
  updateHistoryButtons();
  studio.evaluator.schedule(studio.params, {immediately});
}

function updateHistoryButtons() {
  $("undo").disabled = !studio.history.canUndo();
  $("redo").disabled = !studio.history.canRedo();
}

function travel(direction) {
  const params = direction < 0 ? studio.history.undo() : studio.history.redo();
  if (!params) return;
  studio.params = params;
  studio.form.setValues(params);
  if (studio.kind === "pricking") studio.views.setPoints(getPath(params, "trajectory.points") || []);
  updateHistoryButtons();
  studio.evaluator.schedule(params, {immediately: true});
}

function pin(on) {
  studio.pinned = on && studio.answer ? {answer: studio.answer, params: clone(studio.answerParams)} : null;
  $("pin").hidden = Boolean(studio.pinned);
  $("unpin").hidden = !studio.pinned;
  document.body.classList.toggle("has-pinned", Boolean(studio.pinned));
  redraw();
}

function bindKeys() {
  document.addEventListener("keydown", (event) => {
    if (!(event.ctrlKey || event.metaKey) || event.key.toLowerCase() !== "z" && event.key.toLowerCase() !== "y") return;
    event.preventDefault();   // the page's undo, over every edit, not one input's own
    const redo = event.key.toLowerCase() === "y" || event.shiftKey;
    travel(redo ? 1 : -1);
  });
}

async function start() {
  if (!hasToken()) {
    setStatus("This page needs the token from the address `cadgen studio` printed (…/?token=…).", "error");
    studio.state = "error";
    return;
  }
  setStatus("loading the design...", "busy");
  const [design, schema] = await Promise.all([getJson("/api/design"), getJson("/api/schema")]);
  studio.design = design;
  studio.kind = design.kind;
  studio.params = clone(design.params);
  studio.history = new History(studio.params);
  document.body.dataset.kind = design.kind;
  $("design-name").textContent = design.name;
  $("design-kind").textContent = design.kind;
  $("design-path").textContent = design.path || "bundled example (save it under a new name)";
  $("design-path").title = design.path || "";
  document.title = `${design.name}: cadgen studio`;

  studio.form = new ParameterForm($("form"), schema.kinds[design.kind], (path, value) => {
    setPath(studio.params, path, value);
    edited(path);
  });
  studio.form.setValues(studio.params);
  const grid = $("grid");
  if (design.kind === "pricking") {
    studio.views = new PrickingViews(grid, (points) => {
      setPath(studio.params, "trajectory.points", points);
      studio.views.setPoints(points);
      edited("drag", {immediately: true});
    });
  } else {
    studio.views = new PlantingViews(grid);
  }
  const animation = panel(grid, "panel-animation", "Animation through one carrier turn",
    "Play, pause, drag the slider, pick a speed; the timeline marks the events (click one to go there).");
  animation.parentElement.classList.add("wide");
  studio.player = new AnimationPlayer(animation);
  const buildBody = panel(grid, "panel-build", "Build");
  buildBody.parentElement.classList.add("wide");
  studio.build = new BuildPanel($("build"), buildBody, () => clone(studio.params),
                                (problems) => studio.form.showProblems(problems));
  studio.save = new SaveControls({save: $("save"), saveAs: $("save-as"), form: $("save-as-form"),
                                  name: $("save-as-name"), overwrite: $("save-as-overwrite"),
                                  status: $("save-status")},
                                 design, () => clone(studio.params),
                                 (problems) => studio.form.showProblems(problems));
  studio.evaluator = new Evaluator({
    onStart: () => setStatus("evaluating...", "busy"), onResult, onProblems, onFailure,
  });
  $("undo").addEventListener("click", () => travel(-1));
  $("redo").addEventListener("click", () => travel(1));
  $("pin").addEventListener("click", () => pin(true));
  $("unpin").addEventListener("click", () => pin(false));
  bindKeys();
  updateHistoryButtons();
  studio.evaluator.schedule(studio.params, {immediately: true});
}

start().catch((error) => {
  setStatus(`the studio could not start: ${error.message}`, "error");
  studio.state = "error";
  console.error("cadgen studio:", error);
});
