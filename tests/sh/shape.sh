#!/bin/bash
# The source keeps the shape the project promises its readers:
#   * no C source or header over 1000 lines;
#   * no function over 100 lines;
#   * no file includes another module's private header ("../x/...");
#   * library code (src/base, geom, io, trace, par, view/model, view/render) installs no
#     signal handler, never calls abort() or exit(), and reads no PDT_TEST_* variable
#     outside the test hook (src/base/testhook.c);
# with two named exceptions: the option parser prints usage (src/base/opts.c, both
# programs' front end) and pdt_comm_abort ends the job on the CLI's request.
# The checker is then run on a small tree that breaks each rule and must report each.
source "$(dirname "$0")/lib.sh"

CHECKER=$TMP/shape.py
cat > "$CHECKER" <<'EOF'
import os, re, sys

root = sys.argv[1]
LIB = ("src/base", "src/geom", "src/io", "src/trace", "src/par", "src/view/model",
       "src/view/render")
FORBIDDEN = re.compile(r"\b(sigaction|signal|abort|exit|_exit)\s*\(")
TESTVAR = re.compile(r"getenv\s*\(\s*\"PDT_TEST_")
ALLOWED_EXIT = {("src/par/comm_mpi.c", "pdt_comm_abort")}
problems = []

def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    return re.sub(r"\"(?:[^\"\\\n]|\\.)*\"", lambda m: m.group(0) if "PDT_TEST_" in m.group(0) else '""', text)

def functions(lines):
    """(name, first line, length) of every function whose body opens with '{' in column 0."""
    start = None
    for i, l in enumerate(lines):
        if l.startswith("{") and i > 0:
            k = i - 1
            while k > 0 and "(" not in lines[k]:
                k -= 1
            m = re.search(r"(\w+)\s*\(", lines[k])
            start = (m.group(1) if m else "?", i)
        elif l.startswith("}") and start:
            yield start[0], start[1] + 1, i - start[1] - 1
            start = None

def owner(lines, n):
    """Name of the function containing line n (0-based)."""
    name = None
    for fname, first, length in functions(lines):
        if first - 1 <= n <= first + length:
            name = fname
    return name

for dirpath, _, files in os.walk(os.path.join(root, "src")):
    for f in sorted(files):
        if not f.endswith((".c", ".h")):
            continue
        path = os.path.join(dirpath, f)
        rel = os.path.relpath(path, root)
        raw = open(path, errors="replace").read()
        lines = raw.split("\n")
        if len(lines) - 1 > 1000:
            problems.append("%s: %d lines (at most 1000)" % (rel, len(lines) - 1))
        for name, first, length in functions(lines):
            if length > 100:
                problems.append("%s:%d: function %s has %d lines (at most 100)" % (rel, first, name, length))
        for n, l in enumerate(lines):
            if re.match(r"\s*#\s*include\s*\"\.\./", l):
                problems.append("%s:%d: includes another module's private header: %s" % (rel, n + 1, l.strip()))
        if not rel.startswith(LIB):
            continue
        code = strip_comments(raw).split("\n")
        for n, l in enumerate(code):
            m = FORBIDDEN.search(l)
            if m and rel != "src/base/opts.c" and (rel, owner(code, n)) not in ALLOWED_EXIT:
                problems.append("%s:%d: library code calls %s()" % (rel, n + 1, m.group(1)))
            if TESTVAR.search(l) and rel != "src/base/testhook.c":
                problems.append("%s:%d: reads a PDT_TEST_ variable outside the test hook" % (rel, n + 1))
for p in problems:
    print(p)
sys.exit(1 if problems else 0)
EOF

out=$(python3 "$CHECKER" "$ROOT")
if [ -z "$out" ]; then ok "source shape: files, functions, includes, library calls"
else fail "source shape: files, functions, includes, library calls" "$(echo "$out" | head -20 | tr '\n' ';')"; fi

# The checker must see each kind of breakage.
BAD=$TMP/bad
mkdir -p "$BAD/src/geom" "$BAD/src/view/model"
{
    echo '#include "../io/io_internal.h"'
    echo 'static int long_one(void)'
    echo '{'
    for i in $(seq 1 101); do echo "    x += $i;"; done
    echo '}'
    echo 'void f(void)'
    echo '{'
    echo '    if (getenv("PDT_TEST_FAIL")) abort();'
    echo '}'
    for i in $(seq 1 900); do echo "/* filler $i */"; done
} > "$BAD/src/geom/bad.c"
printf 'void g(void)\n{\n    signal(11, 0); /* exit(1) in a comment is fine */\n}\n' > "$BAD/src/view/model/m.c"
bad=$(python3 "$CHECKER" "$BAD")
for want in "bad.c: 1009 lines" "function long_one has 101 lines" "private header" \
            "calls abort()" "PDT_TEST_ variable" "m.c:3: library code calls signal()"; do
    case "$bad" in
        *"$want"*) ok "shape checker reports: $want" ;;
        *) fail "shape checker reports: $want" "got: $(echo "$bad" | tr '\n' ';')" ;;
    esac
done
case "$bad" in *"calls exit()"*) fail "shape checker ignores comments" "$bad" ;; *) ok "shape checker ignores comments" ;; esac

summary
