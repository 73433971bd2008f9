// cadgen studio: the Build button. The server runs the full build in a separate process; its
// progress arrives as server-sent events (one JSON object each), shown stage by stage; the
// finished build links its report and shows its assembly in the 3D view.
import {ApiError, postJson, withToken} from "./api.js";
import {AssemblyViewer} from "./viewer3d.js";

export class BuildPanel {
  constructor(button, body, currentParams, showProblems) {
    this.button = button;
    this.currentParams = currentParams;
    this.showProblems = showProblems;
    this.status = Object.assign(document.createElement("p"), {className: "build-status",
      textContent: "Build runs every stage (gears, cam, solids, sweeps, report) in a separate process."});
    this.status.setAttribute("aria-live", "polite");
    this.stages = Object.assign(document.createElement("ol"), {className: "build-stages"});
    this.links = Object.assign(document.createElement("p"), {className: "build-links"});
    this.viewerBox = document.createElement("div");
    body.append(this.status, this.stages, this.links, this.viewerBox);
    this.viewer = null;
    this.source = null;
    this.rows = new Map();
    this.button.addEventListener("click", () => this.start());
  }

  async start() {
    this.button.disabled = true;
    this.stages.replaceChildren();
    this.links.replaceChildren();
    this.rows.clear();
    this.status.textContent = "starting the build...";
    this.status.dataset.kind = "busy";
    document.getElementById("panel-build").scrollIntoView({behavior: "smooth", block: "nearest"});
    try {
      const job = await postJson("/api/build", {params: this.currentParams()});
      this.listen(job);
    } catch (error) {
      this.button.disabled = false;
      this.status.textContent = `not started: ${error.message}`;
      this.status.dataset.kind = "error";
      if (error instanceof ApiError && error.problems.length) this.showProblems(error.problems);
    }
  }

  listen(job) {
    if (this.source) this.source.close();
    const source = this.source = new EventSource(withToken(job.events));
    this.status.textContent = `build ${job.job} running...`;
    source.onmessage = (message) => {
      const event = JSON.parse(message.data);
      if (event.type === "progress") this.progress(event);
      else if (event.type === "done") { source.close(); this.done(event); }
    };
    source.onerror = () => {   // the stream ended without "done": the server went away
      if (source.readyState === EventSource.CLOSED || !this.button.disabled) return;
      source.close();
      this.button.disabled = false;
      this.status.textContent = "the build's event stream broke off (is the studio still running?)";
      this.status.dataset.kind = "error";
    };
  }

  progress(event) {
    let row = this.rows.get(event.stage);
    if (!row) {
      row = document.createElement("li");
      row.dataset.stage = event.stage;
      this.rows.set(event.stage, row);
      this.stages.appendChild(row);
    }
    row.dataset.status = event.status;
    if (event.outcome) row.dataset.outcome = event.outcome;   // ok, failed or skipped (on "end")
    const steps = event.total ? ` ${event.done}/${event.total}` : "";
    const state = event.status === "end" ? "done" : "running";
    const elapsed = Number.isFinite(event.elapsed_s) ? ` [${event.elapsed_s.toFixed(1)} s]` : "";
    // the server's text is the command line's progress line for the event: shown as it is
    row.textContent = event.text || `${event.stage}: ${state}${steps}${elapsed}`;
  }

  done(event) {
    this.button.disabled = false;
    const verdicts = {0: "passed every target and check", 1: "built, but a target or check failed",
                      2: "the design has problems", 3: "internal error"};
    this.status.textContent = `build finished (exit ${event.exit_code}: ${verdicts[event.exit_code] || "?"})` +
      (event.summary ? `: ${event.summary.split("\n")[0]}` : "") + (event.error ? ` ${event.error}` : "");
    this.status.dataset.kind = event.exit_code === 0 ? "ok" : event.exit_code === 1 ? "note" : "error";
    if (event.report) {
      const link = Object.assign(document.createElement("a"), {href: withToken(event.report),
        target: "_blank", rel: "noopener", textContent: "Open the report"});
      link.id = "build-report-link";
      this.links.replaceChildren(link);
    }
    if (!event.glb) {
      this.links.append(" (no assembly to show: the scene's effects wrote no solids/assembly.glb)");
    } else {
      if (!this.viewer) this.viewer = new AssemblyViewer(this.viewerBox);
      this.viewer.load(withToken(event.glb));
    }
  }
}
