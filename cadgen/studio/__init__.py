"""cadgen studio: the designer's interactive loop in the browser (``cadgen studio [FILE]``).

A local web server (FastAPI on uvicorn, bound to 127.0.0.1, every data route behind a
random token) and a page of plain ES modules: live metrics and curves as values
change, draggable type-value points, the mechanism's animation, save and build.

Modules: :mod:`~cadgen.studio.server` (the app, its guards and routes),
:mod:`~cadgen.studio.payload` (an evaluation as JSON), :mod:`~cadgen.studio.animation`
(the animation with the gears, housings and duckbill), :mod:`~cadgen.studio.schema`
(the parameter schema for the form), :mod:`~cadgen.studio.save` (writing the file back)
and :mod:`~cadgen.studio.builds` (builds in a separate process). Nothing here is imported
by ``import cadgen``: fastapi and uvicorn load only when the studio starts.
"""

from __future__ import annotations

__all__ = ["create_app"]


def __getattr__(name: str):
    if name == "create_app":
        from cadgen.studio.server import create_app

        return create_app
    raise AttributeError(f"module 'cadgen.studio' has no attribute {name!r}")
