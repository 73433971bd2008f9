// cadgen studio: Save (back to the opened file, comments kept by the server) and Save as (a new
// name in the opened file's folder). The written path or the server's error is shown.
import {ApiError, postJson} from "./api.js";

export class SaveControls {
  /**
   * @param {object} elements  {save, saveAs, form, name, overwrite, status}
   * @param {() => object} currentParams
   * @param {(problems: object[]) => void} showProblems
   */
  constructor(elements, design, currentParams, showProblems) {
    Object.assign(this, elements);
    this.design = design;
    this.currentParams = currentParams;
    this.showProblems = showProblems;
    this.save.addEventListener("click", () => {
      if (this.design.writable) this.send(null);
      else this.openForm("The opened design is not writable (a bundled example): save it under a new name.");
    });
    this.saveAs.addEventListener("click", () => this.openForm(""));
    this.form.addEventListener("submit", (event) => {
      event.preventDefault();
      this.send(this.name.value.trim());
    });
    this.form.querySelector(".cancel").addEventListener("click", () => { this.form.hidden = true; });
  }

  openForm(note) {
    this.form.hidden = false;
    if (!this.name.value) this.name.value = `${this.design.name || "design"}.toml`;
    this.name.focus();
    this.name.select();
    if (note) this.report(note, "note");
  }

  report(text, kind) {
    this.status.textContent = text;
    this.status.dataset.kind = kind;
  }

  async send(name) {
    const body = {params: this.currentParams(), as: name || null};
    if (name && this.overwrite.checked) body.overwrite = true;
    this.report("saving...", "busy");
    try {
      const answer = await postJson("/api/save", body);
      this.report(`saved ${answer.path}`, "ok");
      this.status.dataset.path = answer.path;
      if (name) {   // later plain saves go to the new file
        this.design.path = answer.path;
        this.design.writable = true;
        this.form.hidden = true;
        document.getElementById("design-path").textContent = answer.path;
        document.getElementById("design-path").title = answer.path;
      }
    } catch (error) {
      const detail = error instanceof ApiError && error.status === 409
        ? `${error.message.replace(/\.?$/, ".")} Tick "overwrite" to replace it.` : error.message;
      this.report(`not saved: ${detail}`, "error");
      if (error instanceof ApiError && error.problems.length) this.showProblems(error.problems);
      if (error instanceof ApiError && error.field === "as") this.form.hidden = false;
    }
  }
}
