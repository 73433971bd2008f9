"""The report's interactive 3D view of ``solids/assembly.glb``, working offline from the one page.

The page embeds a lighter copy of the GLB (:func:`cadgen.report.view_glb.lighter_glb`:
every part, named and placed as in the file, with fewer vertices and smaller numbers;
the file stays as written) as base64, drawn by a vendored build of three.js
(``vendor/three-viewer.min.js``: WebGLRenderer, GLTFLoader, OrbitControls; its
version and how it was built are in ``vendor/README.md``), inlined with a small
script of ours (``viewer.js``, with ``explode.js``: the explode slider, which moves each part
by the offset its GLB node carries, :mod:`cadgen.solids.explode`): the page fetches nothing,
so it works from an e-mail attachment or an offline laptop. The GLB is in metres (glTF's unit), as
the view is: it is drawn unscaled.

:func:`interactive_sections` is what the page calls: the animation section
(:mod:`cadgen.report.animation`), then this 3D view, with their shared style.
"""

from __future__ import annotations

import base64
import functools
import html
import importlib.resources

from cadgen.report.animation import animation_section
from cadgen.report.html_tables import _section

__all__ = ["THREE_VERSION", "viewer_section", "interactive_sections"]

#: The vendored three.js release (npm ``three``), see ``vendor/README.md``.
THREE_VERSION = "0.187.0"

_GLB_MAGIC = b"glTF"


@functools.cache
def _resource(name: str) -> str:
    return importlib.resources.files("cadgen.report").joinpath(name).read_text(encoding="utf-8")


def _size(count: int) -> str:
    return f"{count / 1e6:.2f} MB" if count >= 1e5 else f"{count / 1e3:.0f} kB"


def viewer_section(glb: bytes | None, light: bytes | None = None) -> str:
    """The 3D view section (``""`` without a GLB): a canvas, the embedded GLB, the scripts.

    The page embeds a lighter copy of the file (:func:`cadgen.report.view_glb.lighter_glb`:
    every part, named and placed as in the file, with fewer vertices), or the file itself
    when it holds more than meshes that copy knows how to thin.

    Parameters
    ----------
    glb : bytes or None
        The assembly as binary glTF (``solids/assembly.glb``), in metres.
    light : bytes, optional
        Its lighter copy, made already (:func:`cadgen.pipeline.gear_cache.view_glb`: a
        build keeps it in its cache); else made here.

    Raises
    ------
    ValueError
        If ``glb`` is not binary glTF.
    """
    if glb is None:
        return ""
    glb = bytes(glb)
    if not glb.startswith(_GLB_MAGIC):
        raise ValueError(f"assembly must be binary glTF (starting b'glTF'), not {glb[:4]!r}")
    from cadgen.report.view_glb import TOLERANCE_MM, lighter_glb, vertex_count

    try:
        light = lighter_glb(glb) if light is None else bytes(light)
        shown = (f"a copy thinned for the page ({_size(len(light))}, "
                 f"{vertex_count(light):,} vertices, every vertex within {TOLERANCE_MM:g} mm "
                 f"of the file's faces) of {html.escape('solids/assembly.glb')} "
                 f"({_size(len(glb))}, {vertex_count(glb):,} vertices), embedded")
    except (ValueError, KeyError, IndexError, TypeError) as error:
        light = glb   # a GLB the thinning does not read: the page shows the file itself
        shown = (f"{html.escape('solids/assembly.glb')} ({_size(len(glb))}), embedded as "
                 f"written ({html.escape(str(error))})")
    encoded = base64.b64encode(light).decode("ascii")
    vendor = _resource("vendor/three-viewer.min.js").replace("</script", "<\\/script")
    return _section("view-3d", "3D view of the assembly", (
        f'<p class="note">{shown}: drag to turn, scroll to zoom, right-drag to pan. Housing '
        "covers, and the soil of a field run, are drawn see-through; "
        "\u201cHide covers\u201d takes the covers off to show the gears and shafts. "
        "\u201cExplode\u201d takes the machine apart in its assembly order (0 assembled, 1 "
        "apart): each part moves off what it goes onto the way it goes on, along the shafts "
        "(a shaft out of its base towards the cover's side, the cover above the shafts, the "
        "next housing above that, the gears spread along their shafts), and the arms also "
        "out from the carrier. Drawn with "
        f"three.js {THREE_VERSION} (MIT), inlined: nothing is fetched.</p>"
        '<div class="viewer" id="cadgen-viewer" data-state="loading">'
        '<canvas aria-label="3D view of the assembly"></canvas>'
        '<p class="viewer-message" hidden></p>'
        '<button type="button" class="viewer-home">Reset view</button>'
        '<button type="button" class="viewer-covers" hidden>Hide covers</button>'
        '<label class="viewer-explode" hidden>Explode <input type="range" min="0" max="1" '
        'step="0.01" value="0" aria-label="Explode the assembly: 0 assembled, 1 taken apart">'
        '</label></div>'
        f'<script type="application/octet-stream" id="cadgen-glb">{encoded}</script>'
        f"<script>{vendor}</script><script>{_resource('explode.js')}</script>"
        f"<script>{_resource('viewer.js')}</script>"))


def interactive_sections(animation: dict | None = None, glb: bytes | None = None,
                         light: bytes | None = None) -> list[str]:
    """The page's moving sections: the animation, then the 3D view (of ``light``, the GLB's
    lighter copy, when made already), each only when given.

    The style they share comes once, inside the first of them.
    """
    sections = [s for s in (animation_section(animation), viewer_section(glb, light)) if s]
    if sections:
        head, rest = sections[0].split("</summary>", 1)
        sections[0] = f"{head}</summary><style>{_resource('interactive.css')}</style>{rest}"
    return sections
