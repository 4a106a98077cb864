"""The user documentation holds together: every relative link in README.md and docs/ resolves (file and
heading), no page names internal work items ("stop 12", "issue 27") instead of saying what a thing is, and
the README's commands table keeps one short line per command (the detail lives in docs/howto/)."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
WORK_ITEM = re.compile(r"\b(stop|issue) [0-9]+", re.I)
LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)")
MAX_ROW = 300


def doc_files(root: Path = REPO) -> list[Path]:
    """README.md and every Markdown page under docs/."""
    return [root / "README.md", *sorted((root / "docs").rglob("*.md"))]


def _prose(text: str) -> str:
    """The text without fenced code blocks and inline code spans (links there are not links)."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    return re.sub(r"`[^`\n]*`", "", text)


def slug(heading: str) -> str:
    """GitHub's anchor of a Markdown heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """The heading anchors of a Markdown file (outside code blocks)."""
    body = re.sub(r"^```.*?^```", "", path.read_text(encoding="utf-8"), flags=re.S | re.M)
    return {slug(m.group(1)) for m in re.finditer(r"^#{1,6}\s+(.+?)\s*#*$", body, flags=re.M)}


def broken_links(root: Path = REPO) -> list[str]:
    """Every relative link whose file or heading does not exist, as 'page: target'."""
    bad = []
    for page in doc_files(root):
        for target in LINK.findall(_prose(page.read_text(encoding="utf-8"))):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):      # http:, https:, mailto:
                continue
            path_part, _, anchor = target.partition("#")
            dest = (page.parent / path_part).resolve() if path_part else page
            if not dest.exists():
                bad.append(f"{page.relative_to(root)}: {target} (no such file)")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                bad.append(f"{page.relative_to(root)}: {target} (no such heading)")
    return bad


def work_item_mentions(root: Path = REPO) -> list[str]:
    """Lines of README.md and docs/ that name a work item ("stop 12", "issue 27"), as 'page:line: text'."""
    hits = []
    for page in doc_files(root):
        for n, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            if WORK_ITEM.search(line):
                hits.append(f"{page.relative_to(root)}:{n}: {line.strip()[:80]}")
    return hits


def long_command_rows(root: Path = REPO) -> list[str]:
    """Rows of the README's commands table longer than MAX_ROW characters."""
    text = (root / "README.md").read_text(encoding="utf-8")
    m = re.search(r"^## Commands\n(.*?)(?=^## )", text, flags=re.S | re.M)
    assert m, "README.md has no '## Commands' section"
    rows = [r for r in m.group(1).splitlines() if r.startswith("|")]
    assert len(rows) > 2, "README.md's Commands section has no table"
    return [f"{len(r)} characters: {r[:60]}..." for r in rows if len(r) > MAX_ROW]


def test_every_relative_link_resolves():
    assert broken_links() == []


def test_no_work_item_numbers_in_readme_or_docs():
    assert work_item_mentions() == []


def test_no_work_item_numbers_in_code_comments_or_docstrings():
    hits = [f"{f.relative_to(REPO)}:{n}" for pkg in ("mmg", "ekf", "trials") for f in sorted((REPO / pkg).rglob("*.py"))
            for n, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1) if WORK_ITEM.search(line)]
    assert hits == []


def test_readme_commands_table_has_short_rows():
    assert long_command_rows() == []


@pytest.mark.parametrize("heading, anchor", [
    ("Where the data go", "where-the-data-go"),
    ("`mmg imo`: the IMO manoeuvring standards, and how sure the answer is",
     "mmg-imo-the-imo-manoeuvring-standards-and-how-sure-the-answer-is"),
    ("Peak memory (`bench/bench_memory.py`)", "peak-memory-benchbench_memorypy"),
])
def test_slug_is_githubs(heading, anchor):
    assert slug(heading) == anchor


def test_checks_find_what_they_look_for(tmp_path):
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "a.md").write_text("# Title\n\n[ok](#title) [gone](b.md) [no heading](a.md#nope)\n"
                                            "`[in code](missing.md)` [web](https://example.org)\nSee stop 31.\n")
    row = "| `mmg x` | " + "y" * 400 + " |"
    (tmp_path / "README.md").write_text(f"# R\n\n## Commands\n\n| command | what |\n|---|---|\n{row}\n\n## Next\n")
    assert broken_links(tmp_path) == ["docs/a.md: b.md (no such file)", "docs/a.md: a.md#nope (no such heading)"]
    assert work_item_mentions(tmp_path) == ["docs/a.md:5: See stop 31."]
    assert len(long_command_rows(tmp_path)) == 1
