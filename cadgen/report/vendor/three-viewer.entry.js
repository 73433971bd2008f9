// cadgen report viewer: the parts of three.js 0.187.0 the report's 3D view uses, as one global
// (window.CadgenThree). Built by cadgen/report/vendor/README.md's command.
export { WebGLRenderer, Scene, PerspectiveCamera, HemisphereLight, DirectionalLight, Box3,
         Vector3, Color, MeshStandardMaterial, DoubleSide } from 'three';
export { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
export { OrbitControls } from 'three/addons/controls/OrbitControls.js';
