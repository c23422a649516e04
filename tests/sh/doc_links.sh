#!/bin/bash
# Every link and every cited repository file in the docs and the code comments exists.
#
# Read: README.md, docs/**/*.md, lessons/**/*.md, and the comments of src/, include/,
# tests/ and scripts/ (C and C++ /* */ and //, shell and Python #).  Checked against the
# tree as it is when the test runs:
#   * a Markdown link or image [..](target) that is not a URL: target, relative to the
#     citing file, exists;
#   * a cited path (src/…, include/…, tests/…, scripts/…, docs/…, assets/…, lessons/…,
#     man/…): it exists relative to the repository root or to the citing file (a glob
#     such as tests/unit/test_view*.c must match something); a path whose last part is a
#     placeholder in capitals (lessons/NN-*, RUN/frames) is a pattern, not a file, and
#     lessons/02 names the lesson whose folder is lessons/02-*;
#   * a section cited as `FILE.md §N.M` (docs/algorithm.md §3.4, §3.3–3.8, "§3.5 and
#     §3.10"): FILE.md has a heading numbered N.M; inside docs/algorithm.md a bare §N.M
#     refers to that file.
# Then the checker is run on a small tree with a broken link, a missing file and a
# missing section, in a document, a source file and a public header, and must report each.
source "$(dirname "$0")/lib.sh"

CHECKER=$TMP/doc_links.py
cat > "$CHECKER" <<'EOF'
import glob, os, re, sys

root = os.path.abspath(sys.argv[1])
PREFIXES = ("src", "include", "tests", "scripts", "docs", "assets", "lessons", "man")
PATH_RE = re.compile(r"(?<![\w./$-])((?:%s)/[A-Za-z0-9_.*/+-]*[A-Za-z0-9_*/])" % "|".join(PREFIXES))
LINK_RE = re.compile(r"!?\[(?:[^\]\\]|\\.)*\]\(([^()\s]+)(?:\s+\"[^\"]*\")?\)")
SECT_RE = re.compile(r"([\w./-]*\.md)`?\s*((?:(?:,\s*|\s+and\s+|\s*)§\s?\d+(?:\.\d+)?(?:\s?[–-]\s?§?\d+(?:\.\d+)?)?)+)")
NUM_RE = re.compile(r"§?\s?(\d+(?:\.\d+)?)(?:\s?[–-]\s?§?(\d+(?:\.\d+)?))?")
BARE_SECT_RE = re.compile(r"(?<![\w.`])§\s?(\d+(?:\.\d+)?)(?:\s?[–-]\s?§?(\d+(?:\.\d+)?))?")
placeholder = re.compile(r"^[A-Z][A-Z0-9_]*(?:[-.*].*)?$")

def rel(p):
    return os.path.relpath(p, root)

def sources():
    """(path, [(line number, text)]) for every document and every comment."""
    docs = [os.path.join(root, "README.md")]
    for d in ("docs", "lessons"):
        docs += glob.glob(os.path.join(root, d, "**", "*.md"), recursive=True)
    for p in sorted(set(docs)):
        if os.path.isfile(p):
            with open(p, encoding="utf-8", errors="replace") as f:
                yield p, "md", list(enumerate(f.read().split("\n"), 1))
    for d in ("src", "include", "tests", "scripts"):
        for p in sorted(glob.glob(os.path.join(root, d, "**", "*"), recursive=True)):
            ext = os.path.splitext(p)[1]
            if not os.path.isfile(p) or "/corpus/" in p or "/crashes/" in p:
                continue
            if ext in (".c", ".h", ".cpp", ".cc", ".mjs", ".js"):
                yield p, "c", c_comments(p)
            elif ext in (".sh", ".py") or p.endswith("/Makefile"):
                yield p, "sh", hash_comments(p)

def c_comments(p):
    with open(p, encoding="utf-8", errors="replace") as f:
        text = f.read()
    out = []
    for m in re.finditer(r"/\*.*?\*/|//[^\n]*|\"(?:[^\"\\\n]|\\.)*\"|'(?:[^'\\\n]|\\.)*'", text, re.S):
        s = m.group(0)
        if s[0] in "\"'":
            continue
        line = text.count("\n", 0, m.start()) + 1
        for i, l in enumerate(s.split("\n")):
            out.append((line + i, l))
    return out

def hash_comments(p):
    out = []
    with open(p, encoding="utf-8", errors="replace") as f:
        for n, l in enumerate(f, 1):
            s = l.lstrip()
            if s.startswith("#") and not s.startswith("#!"):
                out.append((n, s))
    if p.endswith(".py"):  # docstrings too
        with open(p, encoding="utf-8", errors="replace") as f:
            text = f.read()
        for m in re.finditer(r'"""(.*?)"""', text, re.S):
            line = text.count("\n", 0, m.start()) + 1
            out += [(line + i, l) for i, l in enumerate(m.group(1).split("\n"))]
    return out

headings = {}
def sections(md):
    if md not in headings:
        nums = set()
        if os.path.isfile(md):
            with open(md, encoding="utf-8", errors="replace") as f:
                for l in f:
                    m = re.match(r"#+\s+§?(\d+(?:\.\d+)*)\.?\s", l)
                    if m:
                        nums.add(m.group(1))
        headings[md] = nums
    return headings[md]

def exists_path(base_dir, target):
    for b in (root, base_dir):
        full = os.path.normpath(os.path.join(b, target))
        if any(c in target for c in "*?["):
            if glob.glob(full, recursive=True):
                return True
        elif os.path.exists(full):
            return True
        elif re.fullmatch(r"\d+", os.path.basename(full)) and glob.glob(full + "-*"):
            return True  # lessons/02: lesson 02, the folder lessons/02-graham
    return False

problems = {"links": [], "files": [], "sections": []}
def report(kind, p, n, msg):
    problems[kind].append("%s:%d: %s" % (rel(p), n, msg))

def check_sections(p, n, md, refs):
    for m in NUM_RE.finditer(refs):
        for num in (m.group(1), m.group(2)):
            if num and num not in sections(md):
                report("sections", p, n, "%s has no section %s" % (rel(md), num))

for p, kind, lines in sources():
    d = os.path.dirname(p)
    in_fence = False
    for n, l in lines:
        if kind == "md" and l.lstrip().startswith("```"):
            in_fence = not in_fence
        if kind == "md" and not in_fence:
            for m in LINK_RE.finditer(l):
                t = m.group(1)
                if re.match(r"^[a-z][a-z0-9+.-]*:", t) or t.startswith("#"):
                    continue
                t = t.split("#")[0]
                if t and not os.path.exists(os.path.normpath(os.path.join(d, t))):
                    report("links", p, n, "link to %s: no such file" % t)
        for m in PATH_RE.finditer(l):
            t = m.group(1).rstrip(".")
            last = t.rstrip("/").split("/")[-1]
            if any(placeholder.match(part) for part in t.split("/")[1:]) or not last:
                continue
            if not exists_path(d, t):
                report("files", p, n, "cites %s: no such file" % t)
        for m in SECT_RE.finditer(l):
            name = m.group(1)
            md = None
            for b in (root, d, os.path.join(root, "docs")):
                c = os.path.normpath(os.path.join(b, name))
                if os.path.isfile(c):
                    md = c
                    break
            if md is None:
                if "/" in name or name == "algorithm.md":
                    report("sections", p, n, "cites %s: no such file" % name)
                continue
            check_sections(p, n, md, m.group(2))
        if rel(p) == os.path.join("docs", "algorithm.md") and not in_fence:
            for m in BARE_SECT_RE.finditer(l):
                check_sections(p, n, p, m.group(0))

rc = 0
for kind, name in (("links", "markdown_links_exist"), ("files", "cited_files_exist"),
                   ("sections", "cited_sections_exist")):
    if problems[kind]:
        rc = 1
        print("not ok - %s" % name)
        for x in problems[kind]:
            print("#   " + x)
    else:
        print("ok - %s" % name)
sys.exit(rc)
EOF

# The repository as it is.
python3 "$CHECKER" "$ROOT" > "$TMP/out.txt"
rc=$?
cat "$TMP/out.txt"
T_PASS=$((T_PASS + $(grep -c '^ok - ' "$TMP/out.txt")))
T_FAIL=$((T_FAIL + $(grep -c '^not ok - ' "$TMP/out.txt")))
[ "$rc" -eq 0 ] || [ "$(grep -c '^not ok - ' "$TMP/out.txt")" -gt 0 ] || fail doc_links_checker_ran "exit $rc"

# The checker must see a broken link, a missing cited file and a missing section.
F=$TMP/fake
mkdir -p "$F/docs" "$F/src/geom"
printf '# A\n\nSee [the guide](docs/guide.md) and [gone](docs/gone.md).\n' > "$F/README.md"
printf '# Guide\n\n## 2. Foundations\n\n### 2.2 Predicates\n\nAlso [up](../README.md).\n' > "$F/docs/guide.md"
printf '# Algo\n\n### 2.3 Ties\n' > "$F/docs/algorithm.md"
printf '/* see docs/algorithm.md §2.3, src/geom/gone.c and src/geom/x.c */\nint x;\n' > "$F/src/geom/x.c"
printf '/* docs/algorithm.md §3.4 */\n' > "$F/src/geom/y.c"
python3 "$CHECKER" "$F" > "$TMP/fake.txt"
if [ $? -ne 0 ] && grep -q 'README.md:3: link to docs/gone.md' "$TMP/fake.txt" &&
   grep -q 'x.c:1: cites src/geom/gone.c' "$TMP/fake.txt" &&
   grep -q 'y.c:1: docs/algorithm.md has no section 3.4' "$TMP/fake.txt" &&
   ! grep -q 'guide.md\|x.c:1: cites src/geom/x.c\|x.c:1: docs/algorithm' "$TMP/fake.txt"; then
    ok checker_finds_broken_link_missing_file_and_section
else
    fail checker_finds_broken_link_missing_file_and_section "$(tr '\n' ' ' < "$TMP/fake.txt")"
fi

# A public header's comment is read too: a cited source file and a cited section that do not
# exist fail the check, on their line; the ones that exist (a multi-line comment's later
# line included) do not.
mkdir -p "$F/include/pdt"
printf '/* pdt: see src/geom/x.c,\n * src/geom/dt_gone.c and docs/algorithm.md §2.3 and §4.1. */\nint z;\n' \
    > "$F/include/pdt/z.h"
printf '// docs/guide.md §2.2 and src/geom/y.c\n' > "$F/include/pdt/w.h"
python3 "$CHECKER" "$F" > "$TMP/fake2.txt"
if [ $? -ne 0 ] && grep -q 'include/pdt/z.h:2: cites src/geom/dt_gone.c' "$TMP/fake2.txt" &&
   grep -q 'include/pdt/z.h:2: docs/algorithm.md has no section 4.1' "$TMP/fake2.txt" &&
   ! grep -q 'z.h:1\|w.h\|section 2.3' "$TMP/fake2.txt"; then
    ok checker_reads_header_comments
else
    fail checker_reads_header_comments "$(tr '\n' ' ' < "$TMP/fake2.txt")"
fi
summary
