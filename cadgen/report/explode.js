// cadgen: the exploded view of the 3D views (the report's viewer.js and the studio's
// viewer3d.js), as window.CadgenExplode. Each placed part's glTF node carries in its extras
// (three.js: userData) "explode", the offset in metres, in the assembly's frame, it takes fully
// exploded: computed from the assembly model (cadgen/solids/explode.py), so here it is only
// interpolated, t = 0 assembled to t = 1 exploded. The offset adds to the node's own placement
// (the pose it was loaded at, or any pose a view gives it), so it composes with a moving view.
(function () {
  "use strict";

  // the parts that explode: [{node, base (its placement's position), offset}]
  function parts(model) {
    var list = [];
    model.traverse(function (node) {
      var offset = node.userData && node.userData.explode;
      if (!offset || offset.length !== 3) return;
      list.push({node: node, base: node.position.clone(), offset: offset});
    });
    return list;
  }

  // each part at t of its way out (t clamped to 0..1); returns t
  function apply(list, t) {
    t = Math.min(1, Math.max(0, Number(t) || 0));
    list.forEach(function (part) {
      part.node.position.set(part.base.x + t * part.offset[0], part.base.y + t * part.offset[1],
                             part.base.z + t * part.offset[2]);
      part.node.updateMatrixWorld(true);
    });
    return t;
  }

  // the framed meshes' boxes at t = 0 with their parts' offsets ([{box, offset}], made once)
  function boxes(T, meshes, list) {
    var offsets = new Map(list.map(function (part) { return [part.node, part.offset]; }));
    return meshes.map(function (mesh) {
      var offset = null;
      for (var node = mesh; node && !offset; node = node.parent) offset = offsets.get(node) || null;
      return {box: new T.Box3().setFromObject(mesh, true), offset: offset || [0, 0, 0]};
    });
  }
  // the corners of those boxes at t (metres)
  function corners(T, framed, t) {
    var points = [];
    framed.forEach(function (item) {
      var lo = item.box.min, hi = item.box.max, o = item.offset;
      for (var k = 0; k < 8; k++) {
        points.push(new T.Vector3((k & 1 ? hi.x : lo.x) + t * o[0], (k & 2 ? hi.y : lo.y) + t * o[1],
                                  (k & 4 ? hi.z : lo.z) + t * o[2]));
      }
    });
    return points;
  }

  // the direction the camera looks from at t: from the views' home direction (the mechanism's
  // plane face on, turned a little) towards APART, where the shaft axes (z), along which the
  // parts come apart, lie across the picture rather than along the line of sight
  var APART = [1.0, 0.45, 0.55];
  function direction(T, home, t) {
    var apart = new T.Vector3(APART[0], APART[1], APART[2]).normalize();
    return home.clone().normalize().multiplyScalar(1 - t).addScaledVector(apart, t).normalize();
  }

  // the tightest view of the points from a direction (the camera's field and aspect; its up,
  // y): {target, distance}, every point in the picture
  function fit(T, camera, points, look) {
    var back = look.clone().normalize(), right = new T.Vector3(0, 1, 0).cross(back).normalize();
    var up = back.clone().cross(right);
    var tanV = Math.tan(Math.PI * camera.fov / 360), tanH = tanV * camera.aspect;
    var u = points.map(function (p) { return p.dot(right); });
    var v = points.map(function (p) { return p.dot(up); });
    var w = points.map(function (p) { return p.dot(back); });
    var mid = function (a) { return (Math.min.apply(null, a) + Math.max.apply(null, a)) / 2; };
    var uc = mid(u), vc = mid(v), wc = mid(w), distance = 0;
    for (var i = 0; i < points.length; i++) {   // the point in front of the target needs more
      distance = Math.max(distance, w[i] - wc + Math.abs(u[i] - uc) / tanH,
                          w[i] - wc + Math.abs(v[i] - vc) / tanV);
    }
    var target = right.multiplyScalar(uc).addScaledVector(up, vc).addScaledVector(back, wc);
    return {target: target, distance: distance};
  }

  // the camera kept on the machine as it goes from t0 to t1: the target follows the tightest
  // view's, the distance its ratio and the direction turns as direction() does, all from the
  // view the reader has (an orbit or a zoom of theirs stays), so nothing leaves the picture
  function follow(T, camera, controls, framed, home, t0, t1) {
    if (!framed.length || t0 === t1) return;
    var look0 = direction(T, home, t0), look1 = direction(T, home, t1);
    var fit0 = fit(T, camera, corners(T, framed, t0), look0);
    var fit1 = fit(T, camera, corners(T, framed, t1), look1);
    var view = camera.position.clone().sub(controls.target)
      .multiplyScalar(fit1.distance / fit0.distance);
    var axis = look0.clone().cross(look1);
    if (axis.lengthSq() > 1e-12) view.applyAxisAngle(axis.normalize(), look0.angleTo(look1));
    controls.target.add(fit1.target.sub(fit0.target));
    camera.position.copy(controls.target).add(view);
    camera.far = Math.max(camera.far, view.length() * 20);
    camera.updateProjectionMatrix();
    controls.update();
  }

  window.CadgenExplode = {parts: parts, apply: apply, boxes: boxes, corners: corners,
                          direction: direction, fit: fit, follow: follow};
})();
