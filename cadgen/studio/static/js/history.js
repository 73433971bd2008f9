// cadgen studio: undo and redo over parameter changes (form edits and point drags alike).
// Snapshots of the whole parameter set: they are small (a few kB) and make undo exact.
import {clone, sameJson} from "./params.js";

/** Keystrokes in one field within this long are one undo step, not one per character. */
const MERGE_MS = 800;
const LIMIT = 200;

export class History {
  constructor(initial) {
    this.past = [];
    this.future = [];
    this.current = clone(initial);
    this.lastSource = null;
    this.lastTime = 0;
  }

  /** Records `params` as the new state after an edit from `source` (a field path or "drag"). */
  record(params, source) {
    if (sameJson(params, this.current)) return false;
    const now = performance.now();
    const merge = source && source === this.lastSource && source !== "drag" &&
      now - this.lastTime < MERGE_MS && this.past.length > 0;
    if (!merge) {
      this.past.push(this.current);
      if (this.past.length > LIMIT) this.past.shift();
    }
    this.current = clone(params);
    this.future = [];
    this.lastSource = source;
    this.lastTime = now;
    return true;
  }

  canUndo() { return this.past.length > 0; }
  canRedo() { return this.future.length > 0; }

  undo() {
    if (!this.canUndo()) return null;
    this.future.push(this.current);
    this.current = this.past.pop();
    this.lastSource = null;
    return clone(this.current);
  }

  redo() {
    if (!this.canRedo()) return null;
    this.past.push(this.current);
    this.current = this.future.pop();
    this.lastSource = null;
    return clone(this.current);
  }
}
