"""The documents a user reads: they stand on their own, their links resolve, and every
command and code block they hold runs.

Environment (set by tests/CMakeLists.txt): ABCUBE_SOURCE_DIR, ABCUBE_BIN (the program),
PYTHONPATH (the built module), ABCUBE_TEST_OUT (a scratch folder).
"""
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(os.environ["ABCUBE_SOURCE_DIR"])
BIN = Path(os.environ["ABCUBE_BIN"])
OUT = Path(os.environ.get("ABCUBE_TEST_OUT", "/tmp")) / "docs"

# Written in two pieces so that this file does not match itself.
OUTSIDE = re.compile("|".join([r"\.\./" + "shared", "/work/" + "shared", r"\.\./" + "seeds"]))


def tracked_files():
    out = subprocess.run(["git", "-C", str(SRC), "ls-files", "-z"], capture_output=True, check=True).stdout
    return [SRC / p for p in out.decode().split("\0") if p]


def documents():
    return [SRC / "README.md"] + sorted((SRC / "docs").rglob("*.md"))


def test_nothing_points_outside_the_repository():
    hits = []
    for path in tracked_files():
        try:
            text = path.read_text(errors="strict")
        except (UnicodeDecodeError, IsADirectoryError, FileNotFoundError):
            continue
        for number, line in enumerate(text.splitlines(), 1):
            if OUTSIDE.search(line):
                hits.append(f"{path.relative_to(SRC)}:{number}: {line.strip()[:100]}")
    assert not hits, "\n".join(hits)


def help_texts():
    texts = {"abcube --help": subprocess.run([BIN, "--help"], capture_output=True, text=True).stdout}
    for command in ["render", "batch", "compare", "info", "export-pov", "crosscheck", "report"]:
        texts[f"abcube {command} --help"] = subprocess.run([BIN, command, "--help"], capture_output=True, text=True).stdout
    return texts


def test_help_and_docstrings_name_no_path_outside():
    texts = help_texts()
    import abcube
    for name in dir(abcube):
        obj = getattr(abcube, name)
        texts[f"abcube.{name}"] = getattr(obj, "__doc__", "") or ""
        for member in dir(obj) if isinstance(obj, type) else []:
            texts[f"abcube.{name}.{member}"] = getattr(getattr(obj, member), "__doc__", "") or ""
    assert all(texts[k] for k in ["abcube --help", "abcube render --help"])
    bad = [k for k, t in texts.items() if OUTSIDE.search(t) or "/work/" in t or "README \"" in t]
    assert not bad, bad


def test_every_help_has_one_style():
    """cli.md: every command's --help in the option table's style: a value's name (INT,
    NUMBER, PATH, NAME, ...), its unit, range and default in words in its line; no raw
    parser types (FLOAT, UINT, TEXT, INT:INT in [a - b]) or =default glued to them; the
    citation once, in abcube --help."""
    raw = re.compile(r"\b(FLOAT|UINT|TEXT)\b|\b[A-Z]+:[A-Z]+\b| in \[|\b(INT|NUMBER|PATH|NAME)=")
    texts = help_texts()
    for name, text in texts.items():
        bad = [line for line in text.splitlines() if raw.search(line)]
        assert not bad, (name, bad)
        assert ("Eveleens" in text) == (name == "abcube --help"), name


def test_readme_is_a_front_page():
    lines = (SRC / "README.md").read_text().splitlines()
    assert len(lines) < 200, len(lines)
    blocks = re.findall(r"```[a-z]*\n(.*?)```", "\n".join(lines[:40]), re.S)
    assert len(blocks) >= 2
    assert "tools/setup.sh" in blocks[0] and "abcube render" in blocks[0], blocks[0]
    assert "tools/setup.sh --test" in blocks[1] and "ctest" in blocks[1], blocks[1]
    ci = (SRC / ".ci/run").read_text()
    assert blocks[1].strip() in ci, "the README's test command is not what .ci/run runs"


def test_every_link_resolves():
    broken = []
    for doc in documents():
        text = re.sub(r"```.*?```", "", doc.read_text(), flags=re.S)
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            if re.match(r"[a-z]+:", target):
                continue  # a web address or mailto: not followed here
            path = target.split("#")[0]
            if path and not (doc.parent / path).exists():
                broken.append(f"{doc.relative_to(SRC)}: {target}")
    assert not broken, "\n".join(broken)


def test_every_option_of_help_is_in_the_cli_page():
    page = (SRC / "docs" / "cli.md").read_text()
    missing = []
    for name, text in help_texts().items():
        for flag in re.findall(r"^\s+(?:-\w, )?(--[a-z][a-z0-9-]*)", text, re.M):
            if flag not in ("--help", "--help-all") and flag not in page:
                missing.append(f"{name}: {flag}")
    assert not missing, "\n".join(missing)


def code_blocks():
    """(document, line, language, code) of every ```sh and ```python block."""
    for doc in documents():
        text = doc.read_text()
        for m in re.finditer(r"^```(sh|python)\n(.*?)^```", text, re.S | re.M):
            yield doc, text[: m.start()].count("\n") + 1, m.group(1), m.group(2)


def runnable(code):
    # The set-up and build commands are what CI itself runs (.ci/run), and installs are
    # tests/install's: a block holding one is read, not run, here.
    return not re.search(r"tools/setup\.sh|cmake |pip install|apt-get", code)


BLOCKS = [b for b in code_blocks() if runnable(b[3])]


def test_the_documents_have_examples():
    assert len(BLOCKS) >= 10, len(BLOCKS)


@pytest.mark.parametrize("doc,line,language,code", BLOCKS,
                         ids=[f"{b[0].relative_to(SRC)}:{b[1]}" for b in BLOCKS])
def test_example_runs(doc, line, language, code, tmp_path):
    # The block runs in a folder of its own, with the repository's scenes and examples
    # beside it, `abcube` on PATH and the module importable, as after an install.
    for name in ["scenes", "examples", "python"]:
        (tmp_path / name).symlink_to(SRC / name)
    # `python3` in a block is the interpreter the module was built for.
    env = dict(os.environ, PATH=f"{BIN.parent}:{Path(sys.executable).parent}:{os.environ['PATH']}")
    if language == "sh":
        command = ["bash", "-euo", "pipefail", "-c", code]
    else:
        command = [sys.executable, "-c", code]
    before = set(tmp_path.rglob("*"))
    r = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=240)
    assert r.returncode == 0, f"{doc.relative_to(SRC)}:{line}: exit {r.returncode}\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}"
    # No image the example renders is black (difference images, heat maps and overlays of
    # disagreement are mostly black when things agree: they are not renders).
    import abcube
    for path in sorted(set(tmp_path.rglob("*")) - before):
        not_a_render = any(word in path.name for word in ("heat", "diff", "crosscheck"))
        if path.suffix in (".png", ".exr") and not path.is_symlink() and "." not in path.stem and not not_a_render:
            image = abcube.read_image(str(path))
            assert image.mean() > 0.01, f"{path.name} from {doc.relative_to(SRC)}:{line} is black ({image.mean():.4f})"


def test_performance_page_holds_current_figures():
    """docs/performance.md gives today's figures and how to measure them again: under 400 lines,
    no commit hashes (git keeps the history), and bench/results holds no file named after a
    commit."""
    def is_hash(word):  # 7 to 40 hex digits, a letter and a digit among them
        return bool(re.fullmatch(r"[0-9a-f]{7,40}", word) and re.search(r"[a-f]", word) and re.search(r"[0-9]", word))

    page = (SRC / "docs" / "performance.md").read_text()
    assert len(page.splitlines()) < 400, len(page.splitlines())
    found = [w for w in re.findall(r"\w+", page) if is_hash(w)]
    assert not found, found
    named = [p.name for p in (SRC / "bench" / "results").iterdir() if any(map(is_hash, re.split(r"[_.-]", p.name)))]
    assert not named, named
    assert is_hash("5f1206c") and not any(map(is_hash, ["seed9000", "1280x720", "deadbeef"]))


def test_product_source_holds_no_history():
    """Comments state invariants and reasons: dates and issue numbers go to commit messages
    and CHANGELOG.md, figures to bench/results and docs/performance.md."""
    out = subprocess.run(["git", "-C", str(SRC), "grep", "-nE", r"20[0-9]{2}-[01][0-9]-[0-3][0-9]|[Ii]ssue [0-9]+",
                          "--", "cpu_core", "host", "include", "python", "shaders"], capture_output=True, text=True)
    assert out.returncode == 1 and not out.stdout, out.stdout[:2000]


# A measurement in a comment: a time (12 ms, 3.5 us), a decimal PSNR (43.91 dB), a bandwidth
# (37 GB/s) or a speed-up (2.1x faster, 30% slower). Limits and derivations (64 MiB, 48 dB)
# are invariants and stay.
MEASUREMENT = re.compile(r"\b[0-9.]+ ?(ms|us|ns|µs)\b|\b[0-9]+\.[0-9]+ ?dB\b|\b[0-9.]+ ?[KMG]i?B/s\b"
                         r"|\b[0-9.]+ ?(x|times|%) (faster|slower|the time)\b")


def comment_of(path, line):
    """The comment part of a source line ("" when none)."""
    marker = "#" if path.suffix == ".py" else "//"
    at = line.find(marker)
    return line[at:] if at >= 0 else ""


def test_product_comments_hold_no_measurements():
    """Comments state invariants and reasons; measurements go to bench/results and
    docs/performance.md, where they are dated by the run that made them."""
    found = []
    for path in product_sources():
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if MEASUREMENT.search(comment_of(path, line)):
                found.append(f"{path.relative_to(SRC)}:{number}: {line.strip()}")
    assert not found, found
    assert MEASUREMENT.search("// renders in 0.7 of the time: 43.91 dB, 12 ms")
    assert not MEASUREMENT.search("// 64 MiB cap; 8-bit images one code apart are 48 dB")


PRODUCT_DIRS = ("cpu_core", "host", "include", "python", "shaders")
MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 80


def product_sources():
    out = subprocess.run(["git", "-C", str(SRC), "ls-files", "--", *PRODUCT_DIRS], capture_output=True, text=True,
                         check=True).stdout.split()
    return [SRC / p for p in out if Path(p).suffix in (".cpp", ".hpp", ".h", ".glsl", ".vert", ".frag", ".comp", ".py")]


def test_product_files_are_short():
    """One concept a unit: no product source file runs past MAX_FILE_LINES lines."""
    long = [f"{p.relative_to(SRC)}: {n} lines" for p in product_sources()
            if (n := len(p.read_text().splitlines())) > MAX_FILE_LINES]
    assert not long, long


def long_functions(lines, limit):
    """(first line, length) of each function of a C++ file longer than `limit` lines, member
    functions defined in a class included. The sources are formatted by .clang-format: a
    function's signature starts at its scope's indent (column 0 outside a class, 2 inside one)
    and its body closes with a lone "}" at that indent, every line between indented further.
    A block inside a function closes the same way and is measured too: it is never longer than
    the function that holds it."""
    out = []
    for end, line in enumerate(lines):
        m = re.fullmatch(r"( *)\}", line.rstrip())
        if not m:
            continue
        indent = m.group(1)
        start = end - 1
        while start >= 0 and not (lines[start].startswith(indent) and lines[start][len(indent):][:1] not in ("", " ", "#")
                                  and not lines[start][len(indent):].startswith("//")):
            start -= 1
        if start >= 0 and end - start + 1 > limit:
            out.append((start + 1, end - start + 1))
    return out


def test_long_functions_sees_members():
    """The length rule's reader finds a long member function in a class, and a long function
    outside one, and passes a short one."""
    body = ["    x += 1;"] * 85
    member = ["class A {", " public:", "  int f() const {"] + body + ["  }", "};"]
    free = ["int g(int x,", "      int y) {"] + body + ["}"]
    short = ["int h() {", "  return 1;", "}"]
    assert long_functions(member, MAX_FUNCTION_LINES) == [(3, 87)]
    assert long_functions(free, MAX_FUNCTION_LINES) == [(1, 88)]
    assert long_functions(short, MAX_FUNCTION_LINES) == []


def test_product_functions_are_short():
    """No C++ function of the product, member functions included, runs past MAX_FUNCTION_LINES lines."""
    long = []
    for path in product_sources():
        if path.suffix in (".cpp", ".hpp", ".h"):
            long += [f"{path.relative_to(SRC)}:{first}: {n} lines"
                     for first, n in long_functions(path.read_text().splitlines(), MAX_FUNCTION_LINES)]
    assert not long, long


def test_shaders_take_shared_constants_from_the_prelude():
    """Every constant of host/gl/glsl_shared.hpp reaches the shaders' prelude (gl_program.cpp),
    and no shader states a binding number or defines one of those names itself: C++ and
    GLSL cannot drift apart."""
    header = (SRC / "host/gl/glsl_shared.hpp").read_text()
    names = re.findall(r"^constexpr \w+ (\w+) =", header, re.M) + ["MASK_COLUMNS", "MASK_ROWS", "MASK_SAMPLES"]
    prelude = set(re.findall(r"ABCUBE_GLSL_CONSTANT\(([A-Z_]+)\)", (SRC / "host/gl/gl_program.cpp").read_text()))
    assert len(names) > 10 and set(names) == prelude, set(names) ^ prelude
    own = re.compile(r"binding\s*=\s*\d|^\s*(const\s+\w+|#define)\s+(" + "|".join(names) + r")\b", re.M)
    stated = [f"{p.name}: {m.group(0).strip()}" for p in sorted((SRC / "shaders").iterdir())
              for m in own.finditer(p.read_text())]
    assert not stated, stated


# A design page explains what its header cannot (reasons, examples, measurements) and links
# to it for the rest: a run of this many words copied from a source comment is a paragraph
# kept in two places, which drift apart.
MAX_SHARED_WORDS = 20


def comment_words(path):
    words = []
    for line in path.read_text().splitlines():
        s = line.strip()
        if s.startswith("//"):
            words += s[2:].replace("`", "").split()
    return words


def test_design_pages_link_their_sources_not_copy_them():
    from difflib import SequenceMatcher
    by_name = {}
    for p in tracked_files():
        if p.suffix in (".hpp", ".cpp", ".frag", ".vert", ".glsl", ".comp"):
            by_name.setdefault(p.name, []).append(p)
    copied = []
    for page in sorted((SRC / "docs/design").glob("*.md")):
        text = page.read_text()
        named = set(re.findall(r"`(?:[\w]+/)*([\w]+\.(?:hpp|cpp|frag|vert|glsl|comp))`", text))
        named |= {Path(link).name for link in re.findall(r"\]\(((?:\.\./)+[\w/]+\.(?:hpp|cpp|frag|vert|glsl))\)", text)}
        body = re.sub(r"[`*|]", "", text).split()
        for source in sorted(p for name in named for p in by_name.get(name, [])):
            match = SequenceMatcher(None, comment_words(source), body, autojunk=False)
            longest = max((b.size for b in match.get_matching_blocks()), default=0)
            if longest >= MAX_SHARED_WORDS:
                copied.append(f"{page.name} <- {source.relative_to(SRC)}: {longest} words")
    assert not copied, copied
