"""The README's two set-up commands are the ones CI and a new user run; the documents' links
resolve; the user guide's library example runs as written."""

import re
from pathlib import Path
from urllib.parse import unquote

from tests.helpers import REFERENCE

ROOT = REFERENCE.parents[1]


def commands():
    text = (ROOT / "README.md").read_text()
    return [line.strip() for line in text.splitlines() if line.startswith("    python3 -m venv")]


def test_two_setup_commands():
    main, tests = commands()
    assert main.endswith("cadgen build params/xin2024-planter.toml")
    assert re.search(r"pytest", tests)


def test_ci_runs_exactly_the_readme_test_command():
    _, tests = commands()
    script = (ROOT / ".ci" / "run").read_text().splitlines()
    assert tests in [line.strip() for line in script]


def test_the_library_api_example_runs_as_written(tmp_path, monkeypatch, capsys):
    # the code block under "The library API" in docs/guide.md, run from the repository with
    # the output folder moved to tmp_path
    guide = (ROOT / "docs" / "guide.md").read_text(encoding="utf-8")
    section = guide.split("## The library API", 1)[1]
    block = re.search(r"\n\n((?:    .*\n)(?:    .*\n|\n)*)", section).group(1)
    code = "\n".join(line[4:] for line in block.splitlines())
    assert "cadgen.build(" in code and "cadgen.evaluate(" in code
    monkeypatch.chdir(ROOT)
    exec(compile(code.replace('"outputs"', repr(str(tmp_path))), "docs/guide.md", "exec"), {})
    printed = capsys.readouterr().out
    assert "trajectory height" in printed and "PASSED" in printed
    assert (tmp_path / "xin2024-planter" / "report.json").exists()


#: Markdown links and images: [text](target) and ![alt](target), outside code.
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def documents():
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def local_targets(path: Path):
    """``(target, resolved path)`` of every relative link of a Markdown file (code left out)."""
    text = path.read_text(encoding="utf-8")
    text = re.sub(r"(?ms)^```.*?^```", "", text)             # fenced blocks
    text = re.sub(r"(?m)^(?: {4}|\t).*$", "", text)          # indented blocks
    text = re.sub(r"`[^`\n]*`", "", text)                   # code spans
    for target in LINK.findall(text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
            continue                                        # a URL, mailto:, an anchor here
        yield target, (path.parent / unquote(target.split("#", 1)[0])).resolve()


def test_every_relative_link_of_the_documents_resolves():
    missing = [f"{path.relative_to(ROOT)}: {target}" for path in documents()
               for target, resolved in local_targets(path) if not resolved.exists()]
    assert not missing, "links to files that are not in the repository:\n" + "\n".join(missing)


def anchors(path: Path) -> set:
    """The heading anchors GitHub gives a Markdown file (``## A `b`: c`` -> ``a-b-c``)."""
    text = re.sub(r"(?ms)^```.*?^```", "", path.read_text(encoding="utf-8"))
    seen: dict = {}
    for heading in re.findall(r"(?m)^#{1,6}\s+(.*?)\s*#*\s*$", text):
        slug = re.sub(r"[^\w\- ]", "", heading.replace("`", "").lower()).replace(" ", "-")
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        yield slug if count == 0 else f"{slug}-{count}"


def test_every_anchor_into_a_document_names_a_heading():
    wrong = []
    for path in documents():
        for target, resolved in local_targets(path):
            if "#" in target and resolved.suffix == ".md" and resolved.exists():
                if target.split("#", 1)[1] not in set(anchors(resolved)):
                    wrong.append(f"{path.relative_to(ROOT)}: {target}")
        text = path.read_text(encoding="utf-8")
        for anchor in re.findall(r"\]\(#([^)\s]+)\)", text):   # anchors into the page itself
            if anchor not in set(anchors(path)):
                wrong.append(f"{path.relative_to(ROOT)}: #{anchor}")
    assert not wrong, "links to headings that do not exist:\n" + "\n".join(wrong)


def test_the_link_check_sees_links():
    readme = dict(local_targets(ROOT / "README.md"))
    assert "docs/guide.md" in readme and "docs/images/planter-overview.png" in readme
    assert all(str(resolved).startswith(str(ROOT)) for resolved in readme.values())


def test_the_readme_stays_a_front_door():
    assert len((ROOT / "README.md").read_text(encoding="utf-8").splitlines()) <= 300
