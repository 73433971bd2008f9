// cadgen report: the 3D view of assembly.glb, embedded in the page (base64), drawn with the
// vendored three.js bundle (window.CadgenThree; cadgen/report/vendor/). Nothing is fetched.
(function () {
  "use strict";
  var root = document.getElementById("cadgen-viewer");
  if (!root) return;
  var message = root.querySelector(".viewer-message");
  // what the view drew, for a reader's console and the tests: each part's name and its box
  // in the scene (metres), as placed by the GLB's nodes
  var state = window.cadgenViewer = {state: "loading", meshes: 0, renders: 0, parts: {}};

  function fail(kind, text) {
    state.state = kind;
    root.setAttribute("data-state", kind);
    message.textContent = text;
    message.hidden = false;
  }

  var T = window.CadgenThree;
  if (!T) { fail("error", "The 3D viewer's script did not load."); return; }
  var canvas = root.querySelector("canvas");
  var renderer;
  try {
    renderer = new T.WebGLRenderer({canvas: canvas, antialias: true, preserveDrawingBuffer: true});
  } catch (error) {
    fail("no-webgl", "This browser cannot draw WebGL, so the 3D view is off; the assembly is " +
         "in solids/assembly.glb beside this report.");
    return;
  }
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  var scene = new T.Scene();
  scene.background = new T.Color(0xf4f5f7);
  var camera = new T.PerspectiveCamera(35, 1, 0.001, 100);
  scene.add(new T.HemisphereLight(0xffffff, 0x8d8577, 1.6));
  var sun = new T.DirectionalLight(0xffffff, 1.8);
  sun.position.set(1, 2, 3);
  scene.add(sun);
  var controls = new T.OrbitControls(camera, canvas);
  var home = null;
  var covers = [];   // the housings' covers (nodes named <housing>-cover...): hideable
  // the explode slider's parts (window.CadgenExplode, explode.js), the framed meshes' boxes
  var E = window.CadgenExplode, exploding = [], framed = [], meshes = [], grounds = [];
  state.explode = 0;

  function render() {
    renderer.render(scene, camera);
    state.renders += 1;
  }
  function resize() {
    var width = Math.max(1, root.clientWidth), height = Math.max(1, canvas.clientHeight);
    renderer.setSize(width, height, false);
    camera.aspect = width / height;
    camera.updateProjectionMatrix();
    render();
  }
  // front view (x forward to the right, y up), turned a little to show the axial stack
  var HOME = new T.Vector3(0.45, 0.25, 1).normalize();
  function frame(fit) {
    // the whole (bounding sphere) in the picture
    var centre = fit.getCenter(new T.Vector3()), size = fit.getSize(new T.Vector3());
    var distance = 0.55 * size.length() / Math.sin(Math.PI * 35 / 360);
    var direction = HOME;
    camera.near = distance / 100;
    camera.far = distance * 20;
    camera.updateProjectionMatrix();
    return {position: centre.clone().addScaledVector(direction, distance), target: centre.clone()};
  }
  function goHome() {
    if (!home) return;
    frame(home.fit);
    camera.position.copy(home.position);
    controls.target.copy(home.target);
    controls.update();
    // then as far apart as the slider has the machine, framed as the slider frames it
    if (state.explode > 0) E.follow(T, camera, controls, framed, HOME, 0, state.explode);
    render();
  }
  function recordParts() {
    meshes.forEach(function (node) {
      var box = new T.Box3().setFromObject(node, true);
      state.parts[node.userData.cadgenName] = box.min.toArray().concat(box.max.toArray());
    });
    // whether every framed part's box lies in the picture (the camera's view of it)
    camera.updateMatrixWorld();
    state.inPicture = !E || !framed.length || E.corners(T, framed, state.explode).every(
      function (corner) {
        var seen = corner.project(camera);
        return Math.abs(seen.x) <= 1 && Math.abs(seen.y) <= 1;
      });
  }
  function explodeTo(value) {
    var t = state.explode;
    state.explode = E.apply(exploding, value);
    E.follow(T, camera, controls, framed, HOME, t, state.explode);
    // the soil is no part of the machine: off while it is apart
    grounds.forEach(function (node) { node.visible = state.explode === 0; });
    recordParts();
    render();
  }

  var text = document.getElementById("cadgen-glb").textContent.replace(/\s+/g, "");
  var binary = atob(text), bytes = new Uint8Array(binary.length);
  for (var i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
  new T.GLTFLoader().parse(bytes.buffer, "", function (gltf) {
    var model = gltf.scene;   // in metres, glTF's unit, as the GLB is written
    var fit = new T.Box3(), framedMeshes = [];
    model.updateMatrixWorld(true);
    model.traverse(function (node) {
      if (!node.isMesh) return;
      // the file's node name (three.js keeps it in userData: its own name drops the "/" of
      // "bought/...")
      var name = node.userData.name || node.name ||
        (node.parent && (node.parent.userData.name || node.parent.name)) || "";
      // the GLB carries a material per kind of part (housings and soil see-through): keep it,
      // drawn from both sides since a housing's cavity faces inwards
      if (node.material) node.material.side = T.DoubleSide;
      state.meshes += 1;
      node.userData.cadgenName = name;
      meshes.push(node);
      if (/-cover(-|$)/.test(name)) covers.push(node);
      if (!/^ground/.test(name)) {   // the soil slab is wide: not framed
        fit.expandByObject(node);
        framedMeshes.push(node);
      } else {
        grounds.push(node);
      }
    });
    if (fit.isEmpty()) fit.setFromObject(model);
    scene.add(model);
    home = frame(fit);
    home.fit = fit;
    if (E) {
      exploding = E.parts(model);
      framed = E.boxes(T, framedMeshes, exploding);
    }
    controls.addEventListener("change", render);
    goHome();
    resize();
    recordParts();
    state.covers = covers.length;
    state.exploding = exploding.length;
    if (covers.length) root.querySelector(".viewer-covers").hidden = false;
    if (exploding.length) root.querySelector(".viewer-explode").hidden = false;
    state.state = "ready";
    root.setAttribute("data-state", "ready");
  }, function (error) {
    fail("error", "The embedded assembly could not be read: " + error);
  });

  root.querySelector(".viewer-home").addEventListener("click", goHome);
  root.querySelector(".viewer-explode input").addEventListener("input", function (event) {
    if (exploding.length) explodeTo(event.target.value);
  });
  root.querySelector(".viewer-covers").addEventListener("click", function (event) {
    var hide = covers.length && covers[0].visible;
    covers.forEach(function (node) { node.visible = !hide; });
    state.coversHidden = hide;
    event.target.textContent = hide ? "Show covers" : "Hide covers";
    render();
  });
  if (window.ResizeObserver) new ResizeObserver(resize).observe(root);
  window.addEventListener("beforeprint", render);
})();
