// cadgen studio: the 3D view of a build's assembly.glb, with the report's vendored three.js
// bundle (window.CadgenThree, served at /static/vendor/three-viewer.min.js). The same framing
// and the same cover rule as the report's viewer (cadgen/report/viewer.js, which reads a GLB
// embedded in its page; here the GLB is loaded from the build's /files URL with the token), and
// the same explode slider (window.CadgenExplode: cadgen/report/explode.js, served at
// /static/vendor/explode.js; the offsets are in the GLB's nodes).

// front view (x forward to the right, y up), turned a little to show the axial stack
const HOME = [0.45, 0.25, 1];

export class AssemblyViewer {
  constructor(container) {
    this.root = document.createElement("div");
    this.root.className = "viewer";
    this.root.dataset.state = "empty";
    this.canvas = document.createElement("canvas");
    this.canvas.setAttribute("aria-label", "3D view of the assembly: drag to orbit, wheel to zoom");
    this.message = document.createElement("p");
    this.message.className = "viewer-message";
    this.message.hidden = true;
    const buttons = document.createElement("div");
    buttons.className = "viewer-buttons";
    this.homeButton = Object.assign(document.createElement("button"), {type: "button", textContent: "Home view"});
    this.coversButton = Object.assign(document.createElement("button"),
      {type: "button", textContent: "Hide housing covers", hidden: true});
    this.coversButton.setAttribute("aria-pressed", "false");
    buttons.append(this.homeButton, this.coversButton);
    this.explodeLabel = Object.assign(document.createElement("label"),
      {className: "viewer-explode", textContent: "Explode ", hidden: true});
    this.explodeInput = Object.assign(document.createElement("input"),
      {type: "range", min: "0", max: "1", step: "0.01", value: "0"});
    this.explodeInput.setAttribute("aria-label", "Explode the assembly: 0 assembled, 1 taken apart");
    this.explodeLabel.append(this.explodeInput);
    this.root.append(this.canvas, buttons, this.explodeLabel, this.message);
    container.appendChild(this.root);
    this.state = {state: "empty", meshes: 0, covers: 0, coversHidden: false, explode: 0, exploding: 0};
    this.exploding = [];
    this.framed = [];
    this.grounds = [];
    this.homeButton.addEventListener("click", () => this.goHome());
    this.coversButton.addEventListener("click", () => this.toggleCovers());
    this.explodeInput.addEventListener("input", () => this.explodeTo(this.explodeInput.value));
  }

  fail(kind, text) {
    this.state.state = kind;
    this.root.dataset.state = kind;
    this.message.textContent = text;
    this.message.hidden = false;
  }

  setUp() {
    const T = window.CadgenThree;
    if (!T) { this.fail("error", "The 3D viewer's script did not load."); return false; }
    if (this.renderer) return true;
    try {
      this.renderer = new T.WebGLRenderer({canvas: this.canvas, antialias: true, preserveDrawingBuffer: true});
    } catch (error) {
      this.fail("no-webgl", "This browser cannot draw WebGL; the assembly is in the build's solids/assembly.glb.");
      return false;
    }
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.scene = new T.Scene();
    this.scene.background = new T.Color(0xf4f5f7);
    this.camera = new T.PerspectiveCamera(35, 1, 0.001, 100);
    this.scene.add(new T.HemisphereLight(0xffffff, 0x8d8577, 1.6));
    const sun = new T.DirectionalLight(0xffffff, 1.8);
    sun.position.set(1, 2, 3);
    this.scene.add(sun);
    this.controls = new T.OrbitControls(this.camera, this.canvas);
    this.controls.addEventListener("change", () => this.render());
    if (window.ResizeObserver) new ResizeObserver(() => this.resize()).observe(this.root);
    return true;
  }

  render() {
    if (this.renderer) this.renderer.render(this.scene, this.camera);
  }

  resize() {
    if (!this.renderer) return;
    const width = Math.max(1, this.root.clientWidth), height = Math.max(1, this.canvas.clientHeight);
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  goHome() {
    if (!this.home) return;
    this.camera.position.copy(this.home.position);
    this.controls.target.copy(this.home.target);
    this.controls.update();
    // then as far apart as the slider has the machine, framed as the slider frames it
    if (this.state.explode > 0) {
      const T = window.CadgenThree;
      window.CadgenExplode.follow(T, this.camera, this.controls, this.framed,
                                  new T.Vector3(...HOME), 0, this.state.explode);
    }
    this.render();
  }

  /** Each part `value` (0 assembled .. 1 apart) of its way out; the camera follows. */
  explodeTo(value) {
    const E = window.CadgenExplode, T = window.CadgenThree;
    if (!E || !this.exploding.length) return;
    const before = this.state.explode;
    this.state.explode = E.apply(this.exploding, value);
    E.follow(T, this.camera, this.controls, this.framed, new T.Vector3(...HOME), before,
             this.state.explode);
    this.grounds.forEach((node) => { node.visible = this.state.explode === 0; });   // no soil apart
    this.render();
  }

  /** Loads the GLB at `url` (already carrying the token), replacing any shown before. */
  load(url) {
    if (!this.setUp()) return;
    const T = window.CadgenThree;
    this.state.state = "loading";
    this.root.dataset.state = "loading";
    this.message.hidden = true;
    new T.GLTFLoader().load(url, (gltf) => {
      if (this.model) this.scene.remove(this.model);
      const model = this.model = gltf.scene;   // metres, glTF's unit
      this.covers = [];
      this.grounds = [];
      const fit = new T.Box3(), framed = [];
      model.updateMatrixWorld(true);
      let meshes = 0;
      model.traverse((node) => {
        if (!node.isMesh) return;
        const name = node.name || (node.parent && node.parent.name) || "";
        if (node.material) node.material.side = T.DoubleSide;   // housings' cavities face inwards
        meshes += 1;
        if (/-cover(-|$)/.test(name)) this.covers.push(node);
        if (/^ground/.test(name)) {
          this.grounds.push(node);
        } else {   // the soil slab is wide: not framed
          fit.expandByObject(node);
          framed.push(node);
        }
      });
      if (fit.isEmpty()) fit.setFromObject(model);
      this.scene.add(model);
      const centre = fit.getCenter(new T.Vector3()), size = fit.getSize(new T.Vector3());
      const distance = 0.55 * size.length() / Math.sin(Math.PI * 35 / 360);
      const direction = new T.Vector3(...HOME).normalize();
      this.home = {position: centre.clone().addScaledVector(direction, distance), target: centre.clone()};
      this.camera.near = distance / 100;
      this.camera.far = distance * 20;
      const E = window.CadgenExplode;   // the new model comes assembled
      this.exploding = E ? E.parts(model) : [];
      this.framed = E ? E.boxes(T, framed, this.exploding) : [];
      this.state.explode = 0;
      this.explodeInput.value = "0";
      this.explodeLabel.hidden = this.exploding.length === 0;
      this.goHome();
      this.resize();
      Object.assign(this.state, {state: "ready", meshes, covers: this.covers.length, coversHidden: false,
                                 explode: 0, exploding: this.exploding.length});
      this.coversButton.hidden = this.covers.length === 0;
      this.coversButton.textContent = "Hide housing covers";
      this.root.dataset.state = "ready";
    }, undefined, (error) => this.fail("error", `The assembly could not be loaded: ${error.message || error}`));
  }

  toggleCovers() {
    const hide = this.covers.length > 0 && this.covers[0].visible;
    this.covers.forEach((node) => { node.visible = !hide; });
    this.state.coversHidden = hide;
    this.coversButton.textContent = hide ? "Show housing covers" : "Hide housing covers";
    this.coversButton.setAttribute("aria-pressed", hide ? "true" : "false");
    this.render();
  }
}
