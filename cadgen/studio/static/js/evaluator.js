// cadgen studio: live evaluation. Changes are debounced; each request gets a sequence number and
// an AbortController, so a slow answer that a newer request has overtaken is dropped (and its
// request cancelled): the page only ever shows the answer to the latest parameters.
import {ApiError, postJson} from "./api.js";

export const DEBOUNCE_MS = 150;

export class Evaluator {
  /**
   * @param {object} handlers  {onStart(), onResult(answer, params), onProblems(error, params),
   *                            onFailure(error)}
   */
  constructor(handlers) {
    this.handlers = handlers;
    this.sequence = 0;
    this.timer = null;
    this.controller = null;
  }

  /** Evaluates `params` after the debounce delay (`immediately`: now, e.g. on a drag's release). */
  schedule(params, {immediately = false} = {}) {
    clearTimeout(this.timer);
    const snapshot = JSON.parse(JSON.stringify(params));
    if (immediately) this.run(snapshot);
    else this.timer = setTimeout(() => this.run(snapshot), DEBOUNCE_MS);
  }

  async run(params) {
    const sequence = ++this.sequence;
    if (this.controller) this.controller.abort();
    const controller = this.controller = new AbortController();
    this.handlers.onStart();
    const started = performance.now();
    try {
      const answer = await postJson("/api/evaluate", {params}, controller.signal);
      if (sequence !== this.sequence) return;   // overtaken by a newer request
      answer.round_trip_ms = performance.now() - started;
      this.handlers.onResult(answer, params);
    } catch (error) {
      if (sequence !== this.sequence || error.name === "AbortError") return;
      if (error instanceof ApiError && error.problems.length) this.handlers.onProblems(error, params);
      else this.handlers.onFailure(error);
    } finally {
      if (sequence === this.sequence) this.controller = null;
    }
  }

}
