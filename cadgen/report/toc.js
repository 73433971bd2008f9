// cadgen report: the table of contents follows the reader (the section in view is marked, and
// kept in sight in the contents), a link opens the folded section it leads to, and the contents'
// buttons fold or unfold every section. Without this script the page reads the same: the
// contents are plain links and every section folds by its own heading (<details>).
(function () {
  "use strict";
  var toc = document.querySelector("nav.toc");
  if (!toc) return;
  var list = toc.querySelector("ol");
  var links = Array.prototype.slice.call(toc.querySelectorAll("ol a[href^='#']"));
  var targets = links.map(function (a) {
    return document.getElementById(a.getAttribute("href").slice(1));
  });
  var folds = Array.prototype.slice.call(document.querySelectorAll("details.fold"));
  var state = window.cadgenToc = {current: null, marks: 0};

  function current() {
    // the last section whose top has passed a line a quarter down the window; at the foot of
    // the page, the last section (a short one never reaches the line)
    var line = window.innerHeight / 4, found = 0;
    for (var i = 0; i < targets.length; i++) {
      if (targets[i] && targets[i].getBoundingClientRect().top <= line) found = i;
    }
    var root = document.documentElement;
    if (window.scrollY > 0 && window.scrollY + window.innerHeight >= root.scrollHeight - 2) {
      found = targets.length - 1;
    }
    return found;
  }

  function mark() {
    var k = current(), link = links[k];
    if (state.current === link.getAttribute("href").slice(1)) return;
    links.forEach(function (a) { a.removeAttribute("aria-current"); });
    link.setAttribute("aria-current", "location");
    state.current = link.getAttribute("href").slice(1);
    state.marks += 1;
    toc.setAttribute("data-current", state.current);
    // keep the marked link in sight inside the contents (a column, or a bar on a narrow window)
    if (list.scrollHeight > list.clientHeight + 1) {
      var top = link.offsetTop - list.offsetTop;
      if (top < list.scrollTop || top + link.offsetHeight > list.scrollTop + list.clientHeight) {
        list.scrollTop = Math.max(0, top - list.clientHeight / 3);
      }
    }
    if (list.scrollWidth > list.clientWidth + 1) {
      var left = link.offsetLeft - list.offsetLeft;
      if (left < list.scrollLeft || left + link.offsetWidth > list.scrollLeft + list.clientWidth) {
        list.scrollLeft = Math.max(0, left - 16);
      }
    }
  }

  var queued = false;
  function later() {
    if (queued) return;
    queued = true;
    window.requestAnimationFrame(function () { queued = false; mark(); });
  }
  if (window.IntersectionObserver) {
    // a section crossing the band at the top of the window is when the marked one may change
    var observer = new IntersectionObserver(later, {rootMargin: "0px 0px -75% 0px",
                                                    threshold: [0, 1]});
    targets.forEach(function (t) { if (t) observer.observe(t); });
  }
  window.addEventListener("scroll", later, {passive: true});   // the foot of the page
  window.addEventListener("resize", later);

  function open(id) {
    var target = id && document.getElementById(id);
    var fold = target && target.querySelector("details.fold");
    if (fold) fold.open = true;
  }
  links.forEach(function (a) {
    a.addEventListener("click", function () { open(a.getAttribute("href").slice(1)); });
  });
  if (window.location.hash) open(window.location.hash.slice(1));
  window.addEventListener("hashchange", function () { open(window.location.hash.slice(1)); });

  var controls = toc.querySelector(".toc-fold");
  if (controls) {
    controls.hidden = false;
    controls.addEventListener("click", function (event) {
      var how = event.target.getAttribute("data-fold");
      if (!how) return;
      folds.forEach(function (d) { d.open = how === "open"; });
      later();
    });
  }
  // a printed page holds every section: open the folded ones while printing
  var reopen = [];
  window.addEventListener("beforeprint", function () {
    reopen = folds.filter(function (d) { return !d.open; });
    reopen.forEach(function (d) { d.open = true; });
  });
  window.addEventListener("afterprint", function () {
    reopen.forEach(function (d) { d.open = false; });
    reopen = [];
  });
  mark();
})();
