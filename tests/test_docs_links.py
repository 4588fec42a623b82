"""The documentation's relative links: every one in README.md and docs/ leads to a file of the
repository, every ``#anchor`` to a heading of its target (GitHub's heading slugs), and no page
points to the old out-of-repository contract file (``hw-spec.md``): the contract is
docs/contract.md.

Only what GitHub renders as a link is checked: inline links and images, reference
definitions and HTML ``href``/``src`` attributes, outside code blocks and code spans. Links
with a scheme (``https:``, ``mailto:``) are not followed.
"""

import re
import unicodedata
from pathlib import Path
from urllib.parse import unquote

import pytest

ROOT = Path(__file__).resolve().parent.parent

#: Text that must not appear in any page: the contract used to live outside the repository.
OLD_CONTRACT = "hw-spec"


def doc_files():
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def doc_id(path):
    return path.relative_to(ROOT).as_posix()


# --- Markdown, as far as links and headings need it ---------------------------------------------

_FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})")
_CODE_SPAN = re.compile(r"(?<!`)(`+)(?!`)(.+?)(?<!`)\1(?!`)", re.DOTALL)
_INLINE_LINK = re.compile(
    r"!?\[(?:[^\[\]\\]|\\.|\[[^\[\]]*\])*\]"  # [text] or ![alt], one level of nested brackets
    r"\(\s*(<[^>\n]*>|[^\s()]*(?:\([^\s()]*\)[^\s()]*)*)"  # (destination
    r"(?:\s+(?:\"[^\"]*\"|'[^']*'|\([^)]*\)))?\s*\)"  # optional "title")
)
_REFERENCE_DEF = re.compile(r"^ {0,3}\[[^\]]+\]:\s*(<[^>\n]*>|\S+)", re.MULTILINE)
_HTML_ATTR = re.compile(
    r"<(?:a|img)\b[^>]*?\s(?:href|src)\s*=\s*[\"']([^\"']*)[\"']", re.IGNORECASE
)
_HTML_ID = re.compile(r"<[a-z][^>]*?\s(?:id|name)\s*=\s*[\"']([^\"']*)[\"']", re.IGNORECASE)
_ATX = re.compile(r"^ {0,3}(#{1,6})(?:[ \t]+(.*?))?(?:[ \t]+#+)?[ \t]*$")
_SETEXT = re.compile(r"^ {0,3}(=+|-+)[ \t]*$")
_SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")


def _blank(text):
    """``text`` with every character but newlines replaced by a space (offsets kept)."""
    return re.sub(r"[^\n]", " ", text)


def in_code_block(lines):
    """For each line: is it part of a fenced code block (fences included)?"""
    mask = []
    fence = None
    for line in lines:
        m = _FENCE.match(line)
        if fence is None:
            if m:
                fence = m.group(1)
            mask.append(fence is not None)
        else:
            stripped = line.strip()
            if stripped.startswith(fence[0] * len(fence)) and set(stripped) == {fence[0]}:
                fence = None
            mask.append(True)
    return mask


def prose(text):
    """The Markdown source with fenced code blocks and code spans blanked out, so that what
    looks like a link inside code is not taken for one; offsets and line numbers are
    unchanged."""
    lines = text.split("\n")
    text = "\n".join(
        _blank(line) if code else line for line, code in zip(lines, in_code_block(lines))
    )
    # Code spans may run over a line end, but not over a blank line (a paragraph's end).
    return _CODE_SPAN.sub(
        lambda m: m.group(0) if "\n\n" in m.group(0) else _blank(m.group(0)), text
    )


def links(text):
    """``(line number, destination)`` of every link of a Markdown page."""
    source = prose(text)
    found = []
    for pattern in (_INLINE_LINK, _REFERENCE_DEF, _HTML_ATTR):
        for m in pattern.finditer(source):
            dest = m.group(1).strip()
            if dest.startswith("<") and dest.endswith(">"):
                dest = dest[1:-1]
            found.append((source.count("\n", 0, m.start()) + 1, dest))
    return sorted(found)


def heading_text(raw):
    """The text GitHub shows for a heading's source: code spans, links, emphasis and HTML
    tags reduced to their text."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", raw)  # [text](url) -> text
    text = re.sub(r"<[^>]+>", "", text)  # HTML tags
    text = re.sub(r"(`+)(.+?)\1", lambda m: m.group(2).strip(), text)  # `code` -> code
    return text.strip()


def slug(text):
    """GitHub's anchor for a heading text: lower case; letters, digits, ``_`` and ``-`` kept,
    every space a ``-``, everything else dropped (no collapsing of repeated ``-``)."""
    out = []
    for ch in text.lower():
        cat = unicodedata.category(ch)
        if ch == " ":
            out.append("-")
        elif ch == "-" or cat[0] in "LNM" or cat == "Pc":
            out.append(ch)
    return "".join(out)


def anchors(text):
    """Every ``#anchor`` a Markdown page offers: its headings' slugs (a repeated slug gets
    ``-1``, ``-2``, ... as on GitHub) and explicit HTML ``id``/``name`` attributes."""
    lines = text.split("\n")
    code = in_code_block(lines)
    titles = []
    for i, line in enumerate(lines):
        if code[i]:
            continue
        m = _ATX.match(line)
        if m:
            titles.append(m.group(2) or "")
        elif (
            i > 0
            and not code[i - 1]
            and _SETEXT.match(line)
            and lines[i - 1].strip()
            and not _ATX.match(lines[i - 1])
            and not _SETEXT.match(lines[i - 1])
            and "|" not in lines[i - 1]
            and not re.match(r"^ {0,3}([-*+]|\d+[.)])\s", lines[i - 1])
        ):
            titles.append(lines[i - 1].strip())
    result = set(_HTML_ID.findall(text))
    seen = {}
    for title in titles:
        base = slug(heading_text(title))
        n = seen.get(base, 0)
        seen[base] = n + 1
        result.add(base if n == 0 else f"{base}-{n}")
    return result


def check_link(page, dest):
    """``None`` if ``dest`` (a link on ``page``) resolves, else what is wrong."""
    if not dest or _SCHEME.match(dest) or dest.startswith("//"):
        return None  # empty, or an absolute URL: not checked here
    path_part, _, fragment = dest.partition("#")
    path_part = unquote(path_part.split("?", 1)[0])
    fragment = unquote(fragment)
    if not path_part:
        target = page
    elif path_part.startswith("/"):
        target = (ROOT / path_part.lstrip("/")).resolve()
    else:
        target = (page.parent / path_part).resolve()
    if not target.is_relative_to(ROOT):
        return f"{dest}: leads outside the repository"
    if not target.exists():
        return f"{dest}: no such file {target.relative_to(ROOT).as_posix()}"
    if not fragment:
        return None
    if target.is_dir():
        return f"{dest}: an anchor on a directory"
    if target.suffix.lower() == ".md":
        if fragment not in anchors(target.read_text(encoding="utf-8")):
            return f"{dest}: no heading with the anchor #{fragment} in {doc_id(target)}"
        return None
    if re.fullmatch(r"L\d+(-L\d+)?", fragment):  # a line of a source file
        return None
    return f"{dest}: #{fragment} is not a heading or line anchor of {doc_id(target)}"


# --- The checker itself --------------------------------------------------------------------------


@pytest.mark.parametrize(
    "heading,expected",
    [
        ("Latency (clock edges)", "latency-clock-edges"),
        ("The `pysim` backend", "the-pysim-backend"),
        ("Published bugs, fixed and tested", "published-bugs-fixed-and-tested"),
        (
            "`model` backend (`fpga_robotics.sim.backends.model.ModelBackend`)",
            "model-backend-fpga_roboticssimbackendsmodelmodelbackend",
        ),
        ("`[[room.furniture]]`", "roomfurniture"),
        ("Summary fields (`--summary PATH`)", "summary-fields---summary-path"),
        ("On the robot: ULX3S + OV7670 + GoPiGo3", "on-the-robot-ulx3s--ov7670--gopigo3"),
        ("Two **bold** and [linked](x.md) words", "two-bold-and-linked-words"),
        ("Pixels — and frames", "pixels--and-frames"),
    ],
)
def test_slugs_follow_github(heading, expected):
    assert slug(heading_text(heading)) == expected


def test_anchors_number_repeated_headings_and_skip_code():
    text = "# A\n\n## Notes\n\n```sh\n# not a heading\n```\n\n## Notes\n\nTitle\n=====\n"
    assert anchors(text) == {"a", "notes", "notes-1", "title"}


def test_links_outside_code_only():
    text = (
        'See [the page](docs/a.md#x) and ![img](pic.png "title").\n'
        "`[not](a-link.md)` and\n\n```\n[nor](this.md)\n```\n"
        '[ref]: <docs/b.md>\n<a href="c.md">c</a> [web](https://example.com)\n'
        "[multi\nline](d.md)\n"
    )
    assert links(text) == [
        (1, "docs/a.md#x"),
        (1, "pic.png"),
        (7, "docs/b.md"),
        (8, "c.md"),
        (8, "https://example.com"),
        (9, "d.md"),
    ]


def test_check_link_reports_missing_files_and_anchors():
    readme = ROOT / "README.md"
    assert check_link(readme, "https://example.com/x.md") is None
    assert check_link(readme, "pyproject.toml") is None
    assert check_link(readme, "hw/params.py#L10-L20") is None
    assert "no such file" in check_link(readme, "docs/no-such-page.md")
    assert "outside the repository" in check_link(readme, "../elsewhere.md")
    assert "no heading" in check_link(readme, "#no-such-heading-anywhere")


# --- The documentation ---------------------------------------------------------------------------


@pytest.mark.parametrize("page", doc_files(), ids=doc_id)
def test_relative_links_resolve(page):
    problems = [
        f"{doc_id(page)}:{line}: {problem}"
        for line, dest in links(page.read_text(encoding="utf-8"))
        if (problem := check_link(page, dest)) is not None
    ]
    assert not problems, "broken links:\n" + "\n".join(problems)


@pytest.mark.parametrize("page", doc_files(), ids=doc_id)
def test_no_page_points_to_the_old_contract_file(page):
    hits = [
        f"{doc_id(page)}:{n}: {line.strip()}"
        for n, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1)
        if OLD_CONTRACT in line.lower()
    ]
    assert not hits, (
        "the contract is docs/contract.md (hw-spec.md is not in the repository):\n"
        + "\n".join(hits)
    )


def test_the_readme_links_to_the_contract_page():
    readme = ROOT / "README.md"
    contract = ROOT / "docs" / "contract.md"
    assert contract.is_file()
    targets = {
        (readme.parent / unquote(dest.partition("#")[0])).resolve()
        for _, dest in links(readme.read_text(encoding="utf-8"))
        if dest.partition("#")[0] and not _SCHEME.match(dest)
    }
    assert contract in targets, "README.md does not link to docs/contract.md"
