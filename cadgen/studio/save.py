"""Saving a design from the studio back to TOML, keeping the user's comments and layout.

The page sends the design as JSON (``{"params": {...}}``, the file's tables as
:func:`tomllib.loads` gives them). :func:`save_design` validates it, then edits the
original file's document with tomlkit instead of writing a fresh one, so every comment,
blank line, key order and number spelling the user chose survives:

* a value that differs is replaced in place (numbers compared by value: ``150`` and
  ``150.0`` are the same, and the file keeps its own spelling); its line comment stays
  at the column it had;
* an array is edited item by item: equal items keep their lines and comments, a moved
  type-value point keeps its ``# Q5 ...`` comment, an added point gets a line of its own
  (aligned with :class:`difflib.SequenceMatcher`);
* a key the page sends that the file lacks is added only when it differs from the
  schema's default (or when its presence matters: an accuracy knob the preset would
  otherwise set), under its commented-out line (``# clearance = 2.0``) when the file has
  one, else after the table's last key; a missing table goes at the end of the file;
* a key the file has that the page left out is removed (see :func:`_merge_table`).

Without an original file (the bundled example was opened, which is not writable) the
base document is the bundled template's text (:func:`cadgen.template_text`), so its
comments are there too. "Save as" names a plain ``*.toml`` file inside the opened file's
folder; anything else is a :class:`SaveError` (HTTP 400), an existing file without
``overwrite`` too (409). Before writing, the new text is loaded back and compared with
the parameters sent: the file written always loads to them.
"""

from __future__ import annotations

import difflib
import re
import tomllib
from pathlib import Path
from typing import Annotated, Any, Union, get_args, get_origin

from pydantic import BaseModel

from cadgen import MechanismError

__all__ = ["SaveError", "save_design", "saved_text", "save_target"]


class SaveError(MechanismError):
    """A save the studio refuses, for the HTTP answer.

    Attributes
    ----------
    field : str
        What was wrong, as the API names it: ``"as"`` (the "save as" name), ``"path"``
        (the opened file itself).
    message : str
        One sentence for the designer.
    status : int
        The HTTP status: 400 a name outside the folder, 409 a file that would be
        overwritten or cannot be written.
    """

    def __init__(self, field: str, message: str, status: int = 400):
        self.field = field
        self.message = message
        self.status = status
        super().__init__(f"{field}: {message}")


#: Characters no saved file name may hold: path separators of every platform, a drive
#: colon, and control characters (NUL truncates a path in C, a newline breaks a log line).
_FORBIDDEN_NAME_CHARACTERS = re.compile(r'[/\\:\x00-\x1f\x7f]')
#: The longest file name most filesystems take, in bytes.
_NAME_MAX_BYTES = 255


# --------------------------------------------------------------------------- the target file
def save_target(*, original: Path | None, folder: Path, name: str | None,
                overwrite: bool = False) -> Path:
    """The file a save writes to (symlinks inside the folder followed), or a :class:`SaveError`.

    ``name`` None saves over ``original`` (refused when there is none: a bundled example
    needs a name). Otherwise ``name`` must be a plain, visible ``*.toml`` file name whose
    resolved path stays inside ``folder``; an existing file is refused unless ``overwrite``.
    """
    if name is None:
        if original is None:
            raise SaveError("as", "this design has no file of its own (a bundled example): "
                                  "give a file name to save it as", 400)
        return Path(original).resolve()
    if not isinstance(name, str):
        raise SaveError("as", f"the file name must be a string, not {type(name).__name__}")
    if _FORBIDDEN_NAME_CHARACTERS.search(name):
        raise SaveError("as", f"{name!r} is not a plain file name: no folders, separators "
                              "or control characters")
    if name.startswith("."):
        raise SaveError("as", f"{name!r} would be a hidden file (or a parent folder)")
    if not name.endswith(".toml") or name == ".toml" or name.strip() != name:
        raise SaveError("as", f"{name!r} must be a file name ending in .toml")
    if len(name.encode("utf-8")) > _NAME_MAX_BYTES:
        raise SaveError("as", f"the file name is longer than {_NAME_MAX_BYTES} bytes")
    try:
        folder = Path(folder).resolve(strict=True)
    except OSError as error:
        raise SaveError("as", f"the folder {folder} cannot be used: {error.strerror or error}")
    # resolve() follows a symlink already there: one pointing out of the folder is refused
    target = (folder / name).resolve()
    if not target.is_relative_to(folder):
        raise SaveError("as", f"{name!r} points outside the folder {folder}")
    if target.is_dir():
        raise SaveError("as", f"{name!r} is a folder in {folder}")
    if (folder / name).exists() and not overwrite:
        raise SaveError("as", f"{name} already exists in {folder}: confirm to overwrite it",
                        409)
    return target


# --------------------------------------------------------------------------- saving
def save_design(params: dict, *, original: Path | None, folder: Path, name: str | None,
                overwrite: bool = False) -> Path:
    """Validate ``params`` and write them over ``original`` or as ``folder/name``; the path.

    Parameters
    ----------
    params : dict
        The design as the page holds it (the file's tables as JSON).
    original : Path or None
        The opened file (its comments and layout are kept); None for a bundled example.
    folder : Path
        Where "save as" names a file (the opened file's folder, or the working one).
    name : str or None
        "Save as" this plain ``*.toml`` file name; None saves over ``original``.
    overwrite : bool, default False
        "Save as" may replace an existing file.

    Raises
    ------
    cadgen.ParameterError
        ``params`` do not validate (every problem); nothing is written.
    SaveError
        A name outside the folder (400), an existing file without ``overwrite`` or a file
        that cannot be read or written (409); nothing is written.
    """
    from cadgen import validate_data, write_text_atomic

    validated = validate_data(params)
    target = save_target(original=original, folder=folder, name=name, overwrite=overwrite)
    base = _base_text(params, original, target, saving_as=name is not None)
    text = saved_text(params, base, validated=validated)
    try:
        write_text_atomic(target, text)
    except OSError as error:
        raise SaveError("as" if name is not None else "path",
                        f"cannot write {target}: {error.strerror or error}", 409) from None
    return target


def _base_text(params: dict, original: Path | None, target: Path, *, saving_as: bool) -> str:
    """The document the changes are made in: the opened file, else the bundled template."""
    if original is not None:
        try:
            text = Path(original).read_bytes().decode("utf-8")   # CRLF kept as it is
            same_kind = tomllib.loads(text).get("mechanism") == params.get("mechanism")
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as error:
            if not saving_as:
                raise SaveError("path", f"the file {original} cannot be read as TOML any more "
                                        f"({_one_line(error)}): save as another name", 409)
            same_kind = False
        if same_kind:
            return text
    # no file of the same kind to start from: the bundled example's comments, under the name
    from cadgen import template_text

    kind, design_name = params["mechanism"], params["name"]
    text = template_text(kind, design_name, target.name)
    return text.replace(f"written by `cadgen new {kind} {design_name}` from",
                        "saved by cadgen studio from", 1)


def saved_text(params: dict, base: str, *, validated=None) -> str:
    """``base`` (TOML text) edited to hold ``params``, every comment and layout kept.

    Raises RuntimeError (a bug) when the result would not load to ``params``: checked
    here so that a save never writes a file that means something else.
    """
    import tomlkit

    from cadgen import validate_data

    if validated is None:
        validated = validate_data(params)
    document = tomlkit.parse(base)
    _merge_table(document, params, type(validated), validated, ())
    text = document.as_string()
    if "\r\n" in base:   # a Windows file: the added lines end as the file's own do
        text = re.sub(r"(?<!\r)\n", "\r\n", text)
    reloaded = validate_data(tomllib.loads(text))
    if _comparable(reloaded) != _comparable(validated):
        raise RuntimeError("the saved text does not load to the parameters sent (a bug in "
                           "cadgen.studio.save)")
    return text


def _comparable(params) -> tuple:
    # What a build sees: the values, and which accuracy knobs the file sets (a knob left
    # out takes the preset's value, so its presence matters, not only its value)
    return params.model_dump(), _knobs_set(params)


def _knobs_set(params) -> frozenset:
    from cadgen.params.scene import PRESETS

    found = set()
    for path in {path for knobs in PRESETS.values() for path in knobs}:
        table_name, field = path.split(".")
        table = getattr(params, table_name, None)
        if table is not None and field in table.model_fields_set:
            found.add(path)
    return frozenset(found)


# --------------------------------------------------------------------------- the merge
def _merge_table(table, sent: dict, model: type | None, typed, path: tuple) -> None:
    """Make the tomlkit ``table`` hold ``sent`` (a table of the design), in place.

    ``model`` is the pydantic model of this table and ``typed`` its validated value (for
    the number types to write: an integer the page sent for a float field is written
    as a float).
    """
    import tomlkit

    # A key the file has and the page left out (or sent as null, which TOML cannot say)
    # is removed. The parameters validated, so every such key is optional: the page
    # removed it (or reset it to its default), and kept, the file's value would load
    # instead of the default the page shows.
    for key in [key for key in table if sent.get(key) is None]:
        _delete(table, key)
    for key, value in sent.items():
        if value is None:
            continue
        field_model = _field_model(model, key, value)
        field_typed = _typed_attribute(typed, key)
        if key in table:
            current = table[key]
            if isinstance(value, dict) and isinstance(current, dict):
                _merge_table(current, value, field_model, field_typed, path + (key,))
            elif _same(_unwrap(current), value):
                continue   # the file's spelling (150 or 150.0) stays
            elif isinstance(value, list) and isinstance(current, tomlkit.items.Array):
                _merge_array(current, value, field_typed)
            else:
                _replace_value(table, key, _like(value, field_typed))
        elif _worth_adding(model, key, value, path):
            _add(table, key, value, field_model, field_typed, path + (key,))


def _delete(table, key: str) -> None:
    """Remove ``key``; a removed table's trailing comments stay where it was.

    tomlkit keeps the comments and blank lines that introduce a table at the end of the
    table before it: deleting that one would take the next table's introduction along.
    """
    import tomlkit

    item = table[key]
    body = _body(table)
    if body is None or not isinstance(item, tomlkit.items.Table):
        del table[key]
        return
    trailing = _trailing_lines(item)
    position = next(index for index, (_, entry) in enumerate(body) if entry is item)
    del table[key]
    container = table if _is_document(table) else table.value
    for offset, line in enumerate(trailing):
        _insert_keyless(container, position + offset, line)


def _trailing_lines(table) -> list:
    """The comment and blank-line entries after a table's last entry (its last sub-table's)."""
    body = table.value.body
    end = _after_last_entry(body)
    if end and isinstance(body[end - 1][1], type(table)):
        return _trailing_lines(body[end - 1][1])
    return [entry for key, entry in body[end:] if key is None]


def _insert_keyless(container, index: int, entry) -> None:
    """Insert a comment or whitespace entry at ``index`` of a tomlkit container's body."""
    container._body.insert(index, (None, entry))
    for key, value in container._map.items():   # the keys' positions in the body move on
        if isinstance(value, tuple):
            container._map[key] = tuple(v + 1 if v >= index else v for v in value)
        elif value >= index:
            container._map[key] = value + 1


def _worth_adding(model, key: str, value, path: tuple) -> bool:
    """A key the file lacks is written when it changes what the file means."""
    from cadgen.params.scene import PRESETS

    if any(".".join(path + (key,)) in knobs for knobs in PRESETS.values()):
        return True    # a knob in the file overrides the preset: present, it matters
    has_default, default = _default(model, key)
    if not has_default or default is None:
        return True
    if isinstance(value, dict) and isinstance(default, BaseModel):
        sub_model = type(default)
        return any(_worth_adding(sub_model, sub_key, sub_value, path + (key,))
                   for sub_key, sub_value in value.items() if sub_value is not None)
    return not _same(value, _plain(default))


def _add(table, key: str, value, model, typed, path: tuple) -> None:
    """Add ``key`` to ``table``: a value or inline table in place, a table as a section."""
    import tomlkit

    if not isinstance(value, dict):
        _insert_key(table, key, _like(value, typed))
        return
    if len(path) > 1 and _is_map_of_optionals(model):
        # housing.gearbox1, machine.shafts: a few radii or diameters, an inline table
        # spelled as the bundled files' comments spell it: { O = 50.0, A = 50.0 }
        values = _like(value, typed)
        pairs = ", ".join(f"{sub_key} = {tomlkit.item(sub_value).as_string()}"
                          for sub_key, sub_value in values.items())
        inline = tomlkit.parse(f"{key} = {{ {pairs} }}\n")[key]
        _insert_key(table, key, inline)
        return
    section = tomlkit.table()
    _merge_table(section, value, model, typed, path)
    if len(section) == 0:
        return    # every value the default: the table would say nothing
    if all(isinstance(item, tomlkit.items.Table) for item in section.values()):
        # only sub-tables were written: no empty [cam] header above [cam.timing]
        section = _super_table(section)
    _append_section(table, key, section)


def _super_table(section):
    import tomlkit

    parent = tomlkit.table(is_super_table=True)
    for key, item in section.value.body:
        if key is not None:
            parent.append(key, item)
    return parent


def _append_section(table, key: str, section) -> None:
    """A new ``[table]`` at the end of its parent (the document: the end of the file)."""
    body = _body(table)
    if body is None:
        table[key] = section
        return
    if not _is_document(table):
        # before the parent's trailing comments and blank lines: they introduce what follows
        index = _after_last_entry(body)
        if index < len(body):
            _insert_at(table, index, key, section)
            return
    table.append(key, section)


def _insert_key(table, key: str, item) -> None:
    """Insert a key-value under its commented-out line (``# key = ...``), else after the
    table's last key-value, so it is not put below comments that introduce the next table."""
    body = _body(table)
    if body is None:   # tomlkit's placement (see _body)
        table[key] = item
        return
    commented = re.compile(rf"^\s*#\s*{re.escape(key)}\s*=")
    index = next((position + 1 for position, (entry_key, entry) in enumerate(body)
                  if entry_key is None and _is_comment(entry)
                  and commented.match(entry.as_string())), None)
    if index is None:
        index = _after_last_entry(body, values_only=True)
    if index >= len(body):
        table.append(key, item)
    else:
        _insert_at(table, index, key, item)


def _insert_at(table, index: int, key: str, item) -> None:
    import tomlkit

    container = table if _is_document(table) else table.value
    item = tomlkit.item(item)
    container._insert_at(index, key, item)
    if container is not table:
        # a Table mirrors its container's entries in its own dict (tomlkit's Table.__init__)
        dict.__setitem__(table, key, item)


def _after_last_entry(body: list, *, values_only: bool = False) -> int:
    """Index just after the last key (a key-value when ``values_only``) of a container body."""
    import tomlkit

    last = -1
    for position, (entry_key, entry) in enumerate(body):
        if entry_key is None:
            continue
        if values_only and isinstance(entry, (tomlkit.items.Table, tomlkit.items.AoT)):
            break    # sub-tables follow the table's own keys
        last = position
    return last + 1


def _body(table):
    """The entries of a table in file order, or None where tomlkit places keys itself: an
    inline table, or a table the file writes in parts (``[cam]`` ... ``[cam.duckbill]``
    after another table: tomlkit's out-of-order proxy)."""
    import tomlkit

    if _is_document(table):
        return table.body
    if isinstance(table, tomlkit.items.Table):
        return table.value.body
    return None


def _is_document(table) -> bool:
    import tomlkit

    return isinstance(table, tomlkit.TOMLDocument)


def _is_comment(entry) -> bool:
    import tomlkit

    return isinstance(entry, tomlkit.items.Comment)


def _replace_value(table, key: str, value) -> None:
    """Replace a value, its line comment kept at the column it had."""
    import tomlkit

    current = table[key]
    width = len(current.as_string())
    comment_ws = getattr(current.trivia, "comment_ws", "")
    had_comment = bool(getattr(current.trivia, "comment", ""))
    table[key] = value
    new = table[key] if not isinstance(table, tomlkit.items.InlineTable) else None
    if new is not None and had_comment and new.trivia.comment:
        spaces = len(comment_ws) + width - len(new.as_string())
        new.trivia.comment_ws = " " * max(1, spaces)


def _merge_array(array, values: list, typed) -> None:
    """Edit a tomlkit array into ``values``, keeping the lines of the items that stay.

    Items are aligned with the file's (SequenceMatcher on their values): an item equal to
    the file's keeps its text and comment, a changed one (a dragged point) is replaced in
    its line, an added one gets a line of its own, a removed one loses its line.
    """
    typed_items = list(typed) if isinstance(typed, (list, tuple)) else [None] * len(values)
    new_items = [_like(value, item) for value, item in zip(values, typed_items)]
    if "\n" not in array.as_string() and len(values) != len(array):
        array.clear()          # a one-line array: written again on its line
        for item in new_items:
            array.append(item)
        return
    old_keys = [_key(item) for item in _unwrap(array)]
    new_keys = [_key(item) for item in values]
    opcodes = difflib.SequenceMatcher(None, old_keys, new_keys, autojunk=False).get_opcodes()
    for tag, old_start, old_end, new_start, new_end in reversed(opcodes):
        if tag == "equal":
            continue
        common = min(old_end - old_start, new_end - new_start)
        for offset in range(common):
            _set_array_item(array, old_start + offset, new_items[new_start + offset])
        for index in reversed(range(old_start + common, old_end)):
            del array[index]
        for offset, index in enumerate(range(new_start + common, new_end)):
            array.insert(old_start + common + offset, new_items[index])


def _set_array_item(array, index: int, value) -> None:
    """Replace one item of an array, its comment (a multi-line array's) kept in its column."""
    group = array._value[array._index_map[index]]
    width = len(group.value.as_string())
    array[index] = value
    comment = group.comment
    if comment is not None and comment.trivia.indent.strip() == "":
        spaces = len(comment.trivia.indent) + width - len(group.value.as_string())
        comment.trivia.indent = " " * max(1, spaces)


# --------------------------------------------------------------------------- values
def _unwrap(item):
    return item.unwrap() if hasattr(item, "unwrap") else item


def _same(left, right) -> bool:
    """Equal as parameters: numbers by value (150 == 150.0), booleans never numbers."""
    if isinstance(left, bool) or isinstance(right, bool):
        return type(left) is type(right) and left == right
    if isinstance(left, (int, float)) and isinstance(right, (int, float)):
        return left == right
    if isinstance(left, (list, tuple)) and isinstance(right, (list, tuple)):
        return len(left) == len(right) and all(_same(a, b) for a, b in zip(left, right))
    if isinstance(left, dict) and isinstance(right, dict):
        return left.keys() == right.keys() and all(_same(left[k], right[k]) for k in left)
    return type(left) is type(right) and left == right


def _key(value):
    """A hashable stand-in for an array item, equal when :func:`_same` is true."""
    if isinstance(value, bool):
        return ("bool", value)
    if isinstance(value, (int, float)):
        return ("number", float(value))
    if isinstance(value, (list, tuple)):
        return ("array", tuple(_key(item) for item in value))
    if isinstance(value, dict):
        return ("table", tuple(sorted((k, _key(v)) for k, v in value.items())))
    return (type(value).__name__, value)


def _like(value, typed):
    """``value`` as TOML should spell it: an integer becomes a float where the validated
    parameter is a float (JSON from a browser has no ``150.0``); lists item by item."""
    if isinstance(value, bool):
        return value
    if isinstance(value, int) and isinstance(typed, float):
        return float(value)
    if isinstance(value, list):
        items = list(typed) if isinstance(typed, (list, tuple)) and len(typed) == len(value) \
            else [None] * len(value)
        return [_like(item, typed_item) for item, typed_item in zip(value, items)]
    if isinstance(value, dict):
        return {key: _like(item, _typed_attribute(typed, key))
                for key, item in value.items() if item is not None}
    return value


def _plain(value):
    """A schema default as JSON would hold it (tuples as lists, models as dicts)."""
    if isinstance(value, BaseModel):
        return value.model_dump()
    if isinstance(value, tuple):
        return [_plain(item) for item in value]
    return value


def _typed_attribute(typed, key: str):
    return getattr(typed, key, None) if isinstance(typed, BaseModel) else None


# --------------------------------------------------------------------------- the schema
def _default(model, key: str) -> tuple[bool, Any]:
    """``(has a default, the default)`` of ``model.key`` (a missing model or field: none)."""
    field = getattr(model, "model_fields", {}).get(key) if model is not None else None
    if field is None or field.is_required():
        return False, None
    return True, field.get_default(call_default_factory=True)


def _field_model(model, key: str, value) -> type | None:
    """The pydantic model of ``model.key`` when the page sent a table for it.

    Unwraps ``Annotated``, ``X | None`` and discriminated unions (the pitch curve kinds:
    the member whose fields hold every key sent).
    """
    if not isinstance(value, dict) or model is None:
        return None
    field = getattr(model, "model_fields", {}).get(key)
    if field is None:
        return None
    members = _models_in(field.annotation)
    for member in members:
        if set(value) <= set(member.model_fields):
            return member
    return members[0] if members else None


def _models_in(annotation) -> list:
    origin = get_origin(annotation)
    if origin is Annotated:
        return _models_in(get_args(annotation)[0])
    if origin is Union or type(annotation).__name__ == "UnionType":
        return [model for member in get_args(annotation) for model in _models_in(member)]
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return []


def _is_map_of_optionals(model) -> bool:
    """A table of optional values only (envelope radii, shaft diameters): written inline."""
    fields = getattr(model, "model_fields", None)
    return bool(fields) and all(not field.is_required() and field.default is None
                                for field in fields.values())


def _one_line(error: BaseException, limit: int = 160) -> str:
    text = " ".join(str(error).split())
    return text if len(text) <= limit else text[:limit - 3] + "..."
