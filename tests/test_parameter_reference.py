"""docs/parameters.md is what scripts/parameter_reference.py makes of the parameter models now."""

import importlib.util
from pathlib import Path

from cadgen.params import PlantingParameters, PrickingParameters

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "parameter_reference.py"
DOC = ROOT / "docs" / "parameters.md"


def generator():
    spec = importlib.util.spec_from_file_location("parameter_reference", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_committed_reference_is_the_generated_one():
    module = generator()
    expected = module.reference()
    assert expected == module.reference()   # deterministic
    committed = DOC.read_text(encoding="utf-8") if DOC.exists() else ""
    assert committed == expected, (
        f"docs/parameters.md is out of date with the parameter models: regenerate it with\n"
        f"    {module.COMMAND}")


def test_every_key_of_every_table_is_listed():
    text = generator().reference()

    def keys(model, prefix=""):
        for name, field in model.model_fields.items():
            inner = field.annotation
            members = [m for m in getattr(inner, "__args__", (inner,))
                       if isinstance(m, type) and hasattr(m, "model_fields")]
            if members:
                for member in members:
                    yield from keys(member, f"{prefix}{name}.")
            else:
                yield prefix, name

    for kind, model in (("planting", PlantingParameters), ("pricking", PrickingParameters)):
        section = text.split(f'## `mechanism = "{kind}"`', 1)[1].split("\n## ", 1)[0]
        for table, key in keys(model):
            heading = f"### `[{table[:-1]}]`" if table else "### Top level"
            part = section.split(heading, 1)
            assert len(part) == 2, f"{kind}: no table {heading}"
            assert f"\n| `{key}` |" in part[1].split("\n### ", 1)[0], f"{kind}: {table}{key}"
