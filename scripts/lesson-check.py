#!/usr/bin/env python3
"""pdt — verify a lesson's `checks` file against its recorded run(s).

    scripts/lesson-check.py LESSON_DIR RUNS_DIR
    scripts/lesson-check.py --moments LESSON_DIR RUNS_DIR RUN
        (the bookmarks of run RUN for `pdtview --bookmarks`: one line per moment,
        "K<TAB>TITLE<TAB>TEXT": where the lesson opens and every `step` of its checks)
    scripts/lesson-check.py --find DUMP first|last KIND [W ...] [F=V ...]
        (prints the viewer cursor K that shows that event; scripts/lesson.sh
        uses it for the positions `first ...` / `last ...` of lesson.conf)

LESSON_DIR is lessons/NN-name (holds `checks`, the points and lesson.conf);
RUNS_DIR is where scripts/lesson.sh recorded it (build/lessons/NN): one folder
per run holding dump.txt (`pdt trace dump` of the trace) and output.txt (what
the program printed).

Every line of `checks` states one fact the lesson text relies on.  Lines:

    # comment
    run NAME                    following lines are about run NAME (default: the first run)
    at K KIND [W ...] [F=V ...] the K-th event of the run (the K-th line of `pdt trace
                                dump`; the one the viewer describes when its counter
                                reads "K / total") is of kind KIND, has these words right
                                after the kind (e.g. `graham`, a triangle's three
                                points) and these fields
    first KIND [W..] [F=V..] = K
                                the first matching event is the K-th (counter K)
    count KIND [F=V ...] = M    there are exactly M such events (KIND `*` = any kind)
    sum KIND FIELD [W..] [F=V..] = V   (or > V)
                                the FIELD values of the matching events add up to V
    max KIND FIELD [W..] [F=V..] = V
                                the largest FIELD of the matching events is V
    output-lines = M            the program printed M lines (triangles or hull vertices)
    output-has A B C            one printed line is `A B C` (for triangles the order
                                of the three indices as printed: canonical)
    output = A B C ...          hull: the printed vertices, in order
    area2 A B C = V             Area2 of input points A, B, C (0-based) is V
    lift A = Z                  x*x + y*y of input point A is Z
    hull-size = H               the input points have H hull corners
    xrange KIND [W..] [F=V..] = A B
                                the points (pt=) of the matching events have x from A to B
    squares = anti|main         every unit square of the input (four corners among the
                                points) is cut by its anti-diagonal (x+1,y)-(x,y+1),
                                or by its main diagonal, in the printed triangles
    degree A = D                input point A is a corner of D printed triangles
    incircle A B C D = S        sign (+, -, 0; or the exact value) of the in-circle test: + when D is inside
                                the circle through A, B, C (counter-clockwise), i.e. D's
                                lift is below the plane of the lifted A, B, C (the
                                thesis' H has the opposite sign: H > 0 means outside)
    output-same RUN             this run printed exactly what run RUN printed
    elapsed POS .. POS = V ms   the recorded clock (the dump's t=) advances by V ms from the
                                first event to the second, rounded to V's decimals as the
                                merge-tree panel prints it (a merge's time: from its
                                merge-begin to its merge-end)

What the viewer itself shows (from `pdtview --describe`, written by
scripts/lesson.sh into RUNS_DIR/RUN/describe.txt: the window's own functions):

    line POS = "TEXT"           the event line at POS reads exactly TEXT
    line POS ~ "TEXT"           the event line at POS contains TEXT
    code POS = N                the code panel lights line N (as numbered on screen)
    code POS = LISTING N        ... of listing LISTING (graham or srm)
    code K..M = [LISTING] N     ... at every counter from K to M
    code each KIND [W..] [F=V..] = [LISTING] N
                                ... at every event of that kind ("a pop lights line 9")
    phases RANK = A B C ...     the phases rank RANK begins, in order, are A, B, C
                                (each name once, at its first begin; `run` left out;
                                RANK `*`: every rank, the same list; `any`: the phases
                                any rank begins, in the order they first begin)
    start = K                   the lesson's start position (lesson.conf) is cursor K
    begun POS RANK = A B ...    at POS rank RANK (`*`: every rank) has begun phases A, B, ...
                                (where the lesson opens, every rank is where the text says)
    pgdn = A B C ...            PgDn from Home stops at phases A, B, C, in order (a merge
                                level above 0 as merge:1), each where every rank that goes
                                through the phase has begun it (the same in every run)
    strips from PHASE           no rank's strip box is drawn before that rank begins PHASE
    legend hull POS = RANK      at POS the legend's "hull / stack" swatch has rank RANK's colour
                                (that of the hull drawn thickest: the last one built)
    step N POS                  step N of the text's "In the viewer" list is about the moment
                                POS: a bookmark of the window (b / Shift+b) whose notes pane
                                shows that step's text (`--moments` writes them)
    listing LISTING             the text holds the panel's pseudo-code LISTING line for line
                                (an indented block, numbers and all)

POS is a counter K (the viewer at "K / total"), `start` (where the lesson opens), `end` or
`first KIND [W..] [F=V..]` / `last ...` (as in lesson.conf: stable across runs of
several ranks).

Fields F=V are compared with the fields of the dump line (same names as
`pdt trace dump` prints, e.g. pt=5 cause=3); words W with the words that
follow the kind (`pop graham ...`: graham; `ra-defer 5 8 2 rank=1`: 5 8 2).
Pseudo-fields: @rank=R (the rank that recorded the event), @seq=N (its index
in that rank's file), @phase=NAME and
@level=L (the innermost phase open on that rank when it happened).  Exit 0 when every line holds;
otherwise print every failing line with what was found, exit 1.
"""
import os
import re
import sys


def read_points(path):
    pts = []
    with open(path) as f:
        for line in f:
            line = line.split('#', 1)[0].strip()
            if not line:
                continue
            x, y = line.split()[:2]
            pts.append((int(x), int(y)))
    return pts


def read_conf(path):
    """Global keys and the run names in order (mirrors scripts/lesson.sh)."""
    glob, runs, cur = {}, [], None
    sections = {}
    with open(path) as f:
        for line in f:
            line = line.split('#', 1)[0].strip()
            if not line:
                continue
            m = re.match(r'^\[([A-Za-z0-9_-]+)\]$', line)
            if m:
                cur = m.group(1)
                runs.append(cur)
                sections[cur] = {}
                continue
            k, v = [s.strip() for s in line.split('=', 1)]
            (sections[cur] if cur else glob)[k] = v
    if not runs:
        runs = ['run']
        sections['run'] = {}
    return glob, runs, sections


# `pdt trace dump` prints one line per event, all ranks merged in the order
# the viewer replays them: "r2 #17 t=0.25ms pop graham pt=4 depth=3 cause=5"
# (rank, index of the event in its rank's file, aligned time, the event).
# Events are numbered here by their line, from 0: the viewer's counter K
# ("K / total": K events applied) shows event K - 1.
DUMP_FIRST = 0

EVENT_RE = re.compile(r'^r(\d+)\s+#(\d+)\s+t=\S+\s+(.*)$')


KINDS = {'phase-begin', 'phase-end', 'push', 'pop', 'lift', 'sort', 'delete', 'tri-new',
         'tri-final', 'ra-defer', 'ship', 'discard', 'merge-begin', 'merge-end', 'send',
         'recv', 'hull', 'edge-add', 'edge-del', 'incircle'}


def split_event(toks):
    """Words of an event after its kind -> {'_words': [...], field: value}.
    Three point numbers in a row (a triangle) are rotated to start at the
    smallest, so that `9 30 28` matches however the triangle is reported."""
    fields = {'_words': []}
    for tok in toks:
        if '=' in tok:
            k, v = tok.split('=', 1)
            fields[k] = v
        else:
            fields['_words'].append(tok)
    w = fields['_words']
    for i in range(len(w) - 2):
        if all(t.isdigit() for t in w[i:i + 3]) and (i + 3 == len(w) or not w[i + 3].isdigit()):
            tri = w[i:i + 3]
            k = tri.index(min(tri, key=int))
            w[i:i + 3] = tri[k:] + tri[:k]
            break
    return fields


def parse_dump_line(line):
    """(rank, kind, fields) of one dump line, or None for other lines."""
    m = EVENT_RE.match(line.strip())
    if not m:
        return None
    toks = m.group(3).split()
    if not toks or toks[0] not in KINDS:
        return None
    fields = split_event(toks[1:])
    fields['@rank'] = m.group(1)
    fields['@seq'] = m.group(2)
    return m.group(1), toks[0], fields


def read_dump(path):
    """Events of a dump: {index: (kind, fields, text)} and the indices in
    order.  Adds the pseudo-fields @rank (the recording rank), @phase and
    @level (the innermost phase open on that rank, and its merge level)."""
    events = {}
    order = []
    open_phases = {}
    with open(path) as f:
        for line in f:
            e = parse_dump_line(line)
            if e is None:
                continue
            _, kind, fields = e
            idx = len(order)
            stack = open_phases.setdefault(fields['@rank'], [])
            if kind == 'phase-begin':
                stack.append((fields['_words'][0] if fields['_words'] else '?',
                              fields.get('level', '0')))
            top = stack[-1] if stack else ('-', '0')
            fields['@phase'], fields['@level'] = top
            if kind == 'phase-end' and stack:
                stack.pop()
            events[idx] = (kind, fields, line.rstrip('\n'))
            order.append(idx)
    return events, order


def find(dump, which, spec):
    """Viewer cursor that shows the first/last event matching spec (KIND
    [words] [F=V]): its dump index + 1 - DUMP_FIRST; None if there is none."""
    events, order = read_dump(dump)
    want = parse_fields(spec[1:])
    hits = [i for i in order if match(events[i][0], events[i][1], spec[0], want)]
    if not hits:
        return None
    i = hits[0] if which == 'first' else hits[-1]
    return i + 1 - DUMP_FIRST


def match(kind, fields, want_kind, want):
    """Does an event (kind, fields) have kind want_kind ('*': any), start its
    words with want['_words'] and carry every other field of want?"""
    if want_kind != '*' and kind != want_kind:
        return False
    words = want.get('_words', [])
    if fields['_words'][:len(words)] != words:
        return False
    for k, v in want.items():
        if k != '_words' and fields.get(k) != v:
            return False
    return True


def parse_fields(toks):
    """Words and F=V fields of a check line after its kind; `rank=R` of the
    recording rank is written @rank=R."""
    return split_event(toks)


def area2(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])


def square_diagonals(pts, out):
    """How the output cuts the unit squares whose four corners are input
    points: 'anti' (every square by (x+1,y)-(x,y+1)), 'main' (every one by
    (x,y)-(x+1,y+1)), 'mixed', or 'none' (no such square)."""
    idx = {}
    for i, p in enumerate(pts):
        idx.setdefault(p, i)
    edges = set()
    for t in out:
        v = [int(a) for a in t[:3]]
        for k in range(3):
            edges.add(frozenset((v[k], v[(k + 1) % 3])))
    kinds = set()
    for (x, y), i in idx.items():
        c = [(x + 1, y), (x, y + 1), (x + 1, y + 1)]
        if not all(q in idx for q in c):
            continue
        anti = frozenset((idx[(x + 1, y)], idx[(x, y + 1)])) in edges
        main = frozenset((i, idx[(x + 1, y + 1)])) in edges
        kinds.add('anti' if anti and not main else 'main' if main and not anti else '?')
    if not kinds:
        return 'none'
    return kinds.pop() if len(kinds) == 1 else 'mixed'


def hull_size(pts):
    """Number of corners of the convex hull (collinear boundary points not
    counted), by the monotone chain."""
    q = sorted(set(pts))
    if len(q) < 3:
        return len(q)
    def chain(seq):
        h = []
        for p in seq:
            while len(h) >= 2 and area2(h[-2], h[-1], p) <= 0:
                h.pop()
            h.append(p)
        return h[:-1]
    return len(chain(q) + chain(q[::-1]))


def incircle(a, b, c, d):
    """> 0 when d is inside the circle through a, b, c (counter-clockwise)."""
    m = [(p[0] - d[0], p[1] - d[1]) for p in (a, b, c)]
    m = [(x, y, x * x + y * y) for x, y in m]
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def read_describe(path):
    """pdtview --describe output: (start, {K: (listing, line, text)}, {listing: [lines]},
    {'pgdn': [(K, NAME)], 'box': {rank: K}})."""
    start, ev, lst = None, {}, {}
    more = {'pgdn': [], 'box': {}, 'legend': []}
    with open(path, encoding='utf-8') as f:
        for raw in f:
            t = raw.rstrip('\n').split('\t')
            if t[0] == 'start':
                start = int(t[1])
            elif t[0] == 'listing':
                lst.setdefault(t[1], []).append(t[3])
            elif t[0] == 'event':
                ev[int(t[1])] = (t[2], int(t[3]) if t[3] != '-' else None, t[4])
            elif t[0] == 'pgdn':
                more['pgdn'].append((int(t[1]), t[2]))
            elif t[0] == 'box':
                more['box'][t[1]] = int(t[2])
            elif t[0] == 'legend':
                more['legend'].append((t[1], int(t[2]), int(t[3])))
    return start, ev, lst, more


def resolve_pos(toks, events, order, start):
    """Cursor K of a position: `K`, `start`, `first|last KIND ...`."""
    if toks[0] == 'start':
        if start is None:
            raise AssertionError('no start position recorded')
        return start
    if toks[0] == 'end':
        return len(order)
    if toks[0] in ('first', 'last'):
        want = parse_fields(toks[2:])
        hits = [i for i in order if match(events[i][0], events[i][1], toks[1], want)]
        if not hits:
            raise AssertionError('no event %s' % ' '.join(toks[1:]))
        return (hits[0] if toks[0] == 'first' else hits[-1]) + 1 - DUMP_FIRST
    return int(toks[0])


UNIT_MS = {'ns': 1e-6, 'us': 1e-3, 'µs': 1e-3, 'ms': 1.0, 's': 1e3}


def event_ms(text):
    """The t= of a dump line, in milliseconds."""
    m = re.search(r' t=([0-9.]+)(ns|us|µs|ms|s) ', text + ' ')
    if not m:
        raise AssertionError('no time in "%s"' % text)
    return float(m.group(1)) * UNIT_MS[m.group(2)]


def check_elapsed(line, events, order):
    """elapsed POS .. POS = V ms: the clock between two events, as printed."""
    lhs, _, rhs = line.partition(' = ')
    a, _, b = lhs.split(None, 1)[1].partition(' .. ')
    ka, kb = (resolve_pos(x.split(), events, order, None) for x in (a, b))
    want = rhs.split()[0]
    dec = len(want.partition('.')[2])
    ms = event_ms(events[kb - 1 + DUMP_FIRST][2]) - event_ms(events[ka - 1 + DUMP_FIRST][2])
    if '%.*f' % (dec, ms) != want:
        raise AssertionError('from %d to %d the clock advances by %.4f ms' % (ka, kb, ms))


def lit(want, listing, cl):
    """Does the panel state (listing, line cl) match the wanted [LISTING] N?"""
    got = '%s %s' % (listing, cl if cl else '-')
    return (len(want) == 1 and str(cl if cl else '-') == want[0]) or \
        (len(want) == 2 and got == ' '.join(want))


def check_code_all(lt, want, dev, events, order):
    """`code K..M = [LISTING] N` or `code each KIND ... = [LISTING] N`: the
    panel lights that line at every such cursor; raise naming the others."""
    if lt[0] == 'each':
        spec = parse_fields(lt[2:])
        ks = [i + 1 - DUMP_FIRST for i in order if match(events[i][0], events[i][1], lt[1], spec)]
        if not ks:
            raise AssertionError('no event %s' % ' '.join(lt[1:]))
    else:
        a, b = lt[0].split('..')
        ks = list(range(int(a), int(b) + 1))
    bad = []
    for k in ks:
        if k not in dev:
            raise AssertionError('the viewer has no event %d' % k)
        listing, cl, _ = dev[k]
        if not lit(want, listing, cl):
            bad.append('%d: %s line %s' % (k, listing, cl if cl else '(none)'))
    if bad:
        raise AssertionError('%d of %d cursors light another line: %s' % (
            len(bad), len(ks), ', '.join(bad[:8])))


def phases_begun(events, order, rank):
    """Phase names in the order rank `rank` first begins them ('main': every
    phase any rank begins, in the order they first begin; run left out)."""
    seen = []
    for i in order:
        kind, f, _ = events[i]
        if kind != 'phase-begin' or not f['_words']:
            continue
        name = f['_words'][0]
        if name == 'run' or name in seen:
            continue
        if rank == 'any' or f['@rank'] == rank:
            seen.append(name)
    return seen


def phase_key(fields):
    """`merge:1` for a merge level above 0, else the phase name."""
    name = fields['_words'][0] if fields['_words'] else '?'
    lv = fields.get('level', '0')
    return name if lv == '0' else '%s:%s' % (name, lv)


def begins(events, order):
    """{phase key: {rank: index of its first phase-begin}}."""
    got = {}
    for i in order:
        kind, f, _ = events[i]
        if kind == 'phase-begin':
            got.setdefault(phase_key(f), {}).setdefault(f['@rank'], i)
    return got


def check_begun(k, ranks, names, events, order):
    """At cursor k (events 0..k-1 applied) the ranks have begun every phase."""
    b = begins(events, order)
    allranks = sorted({events[i][1]['@rank'] for i in order}, key=int)
    for name in names:
        for rk in (allranks if ranks == '*' else [ranks]):
            i = b.get(name, {}).get(rk)
            if i is None or i + 1 > k:
                raise AssertionError('at %d rank %s has not begun %s%s' % (
                    k, rk, name, '' if i is None else ' (it does at %d)' % (i + 1)))


def check_pgdn(want, more, events, order):
    """PgDn's stops have these names, each after every rank's begin."""
    got = [n for _, n in more['pgdn']]
    if not got:
        raise AssertionError('pdtview --describe lists no PgDn stops')
    if got != want:
        raise AssertionError('PgDn stops at: %s' % ' '.join(got))
    b = begins(events, order)
    for k, name in more['pgdn']:
        late = [rk for rk, i in b.get(name, {}).items() if i + 1 > k]
        if late:
            raise AssertionError('PgDn stops at %d for %s before rank %s begins it' % (
                k, name, ', '.join(late)))


def check_strips(phase, more, events, order):
    """No strip box is drawn before its rank begins `phase`."""
    b = begins(events, order).get(phase, {})
    for rk, k in sorted(more['box'].items()):
        i = b.get(rk)
        if i is None or k < i + 1:
            raise AssertionError('rank %s\'s strip is drawn from %d, %s' % (
                rk, k, 'it never begins %s' % phase if i is None else
                'before it begins %s (%d)' % (phase, i + 1)))
    if not more['box']:
        raise AssertionError('pdtview --describe lists no strip boxes')


def viewer_steps(text_lines):
    """The "In the viewer" section: (intro, {N: text of numbered item N}), each
    flattened to one line."""
    intro, steps, cur, on = [], {}, None, False
    for l in text_lines:
        if l.startswith('## '):
            on = l.strip() == '## In the viewer'
            continue
        if not on:
            continue
        m = re.match(r'^(\d+)\.\s+(.*)$', l)
        if m:
            cur = int(m.group(1))
            steps[cur] = [m.group(2)]
        elif cur is not None and l.strip():
            steps[cur].append(l.strip())
        elif cur is None and l.strip() and not l.startswith('|'):
            intro.append(l.strip())
    return ' '.join(intro), {k: ' '.join(v) for k, v in steps.items()}


def moments(ldir, rdir, run):
    """Print the bookmarks of run `run`: the start and every `step`."""
    with open(os.path.join(ldir, 'README.md'), encoding='utf-8') as f:
        intro, steps = viewer_steps(f.read().split('\n'))
    d = os.path.join(rdir, run)
    events, order = read_dump(os.path.join(d, 'dump.txt'))
    dstart = read_describe(os.path.join(d, 'describe.txt'))[0]
    out = [(dstart, 'start', intro)] if dstart is not None else []
    cur_run = read_conf(os.path.join(ldir, 'lesson.conf'))[1][0]
    with open(os.path.join(ldir, 'checks'), encoding='utf-8') as f:
        for raw in f:
            toks = raw.split('#', 1)[0].split()
            if toks[:1] == ['run']:
                cur_run = toks[1]
            elif toks[:1] == ['step'] and cur_run == run and int(toks[1]) in steps:
                k = resolve_pos(toks[2:], events, order, dstart)
                out.append((k, 'step %s' % toks[1], steps[int(toks[1])]))
    out[1:] = sorted(out[1:], key=lambda t: int(t[1].split()[1])) if dstart is not None else \
        sorted(out, key=lambda t: int(t[1].split()[1]))
    for k, title, text in out:  # the start, then the steps in the text's order
        print('%d\t%s\t%s' % (k, title, text.replace('\t', ' ')))
    return 0


def quoted(rhs):
    rhs = rhs.strip()
    if len(rhs) < 2 or rhs[0] != '"' or rhs[-1] != '"':
        raise ValueError('the text must be in double quotes: %s' % rhs)
    return rhs[1:-1]


def main():
    if len(sys.argv) == 5 and sys.argv[1] == '--moments':
        return moments(sys.argv[2], sys.argv[3], sys.argv[4])
    if len(sys.argv) >= 5 and sys.argv[1] == '--find':
        k = find(sys.argv[2], sys.argv[3], sys.argv[4:])
        if k is None:
            print('lesson-check: no event %s in %s' % (' '.join(sys.argv[4:]), sys.argv[2]),
                  file=sys.stderr)
            return 1
        print(k)
        return 0
    if len(sys.argv) != 3:
        print(__doc__.strip().split('\n\n')[1], file=sys.stderr)
        return 2
    ldir, rdir = sys.argv[1], sys.argv[2]
    glob, runs, sections = read_conf(os.path.join(ldir, 'lesson.conf'))
    cache = {}

    def run_data(run):
        if run not in cache:
            d = os.path.join(rdir, run)
            events, order = read_dump(os.path.join(d, 'dump.txt'))
            out = []
            op = os.path.join(d, 'output.txt')
            if os.path.exists(op):
                with open(op) as f:
                    out = [l.split() for l in f if l.strip() and not l.startswith('#')]
            pfile = sections[run].get('points', glob.get('points', 'points.txt'))
            pts = read_points(os.path.join(ldir, pfile)) if os.path.exists(
                os.path.join(ldir, pfile)) else []
            dp = os.path.join(d, 'describe.txt')
            desc = read_describe(dp) if os.path.exists(dp) else None
            cache[run] = (events, order, out, pts, desc)
        return cache[run]

    run = runs[0]
    bad = 0
    skipped = 0
    nchecks = 0
    with open(os.path.join(ldir, 'README.md'), encoding='utf-8') as f:
        text_lines = f.read().split('\n')
    with open(os.path.join(ldir, 'checks'), encoding='utf-8') as f:
        lines = list(f)
    for lineno, raw in enumerate(lines, 1):
        line = raw.split('#', 1)[0].strip()
        if not line:
            continue
        toks = line.split()
        where = '%s/checks:%d: %s' % (ldir, lineno, line)
        try:
            if toks[0] == 'run':
                if toks[1] not in runs:
                    raise ValueError('no run %r in lesson.conf' % toks[1])
                run = toks[1]
                continue
            nchecks += 1
            events, order, out, pts, desc = run_data(run)
            ltoks, rhs = toks, None
            if toks[0] == 'step':
                n_step = int(toks[1])
                if n_step not in viewer_steps(text_lines)[1]:
                    raise AssertionError('the text has no step %d under "In the viewer"' % n_step)
                desc = run_data(run)[4]
                k = resolve_pos(toks[2:], events, order, desc[0] if desc else None)
                if not 0 <= k <= len(order):
                    raise AssertionError('step %d: no cursor %d' % (n_step, k))
                continue
            if toks[0] in ('line', 'code', 'start', 'listing', 'begun', 'pgdn', 'strips', 'legend'):
                if desc is None:
                    skipped += 1
                    print('SKIP %s\n     no describe.txt (pdtview is not built)' % where)
                    continue
                dstart, dev, dlst, dmore = desc
                if toks[0] == 'pgdn':
                    check_pgdn(line.partition(' = ')[2].split(), dmore, events, order)
                    continue
                if toks[0] == 'legend':
                    lhs, _, rhs = line.partition(' = ')
                    lt = lhs.split()
                    k = resolve_pos(lt[2:], events, order, dstart)
                    got = [q for what, kk, q in dmore['legend'] if what == lt[1] and kk <= k]
                    if not got or got[-1] != int(rhs):
                        raise AssertionError('at %d the legend\'s %s swatch has rank %s\'s colour'
                                             % (k, lt[1], got[-1] if got else '(no legend line)'))
                    continue
                if toks[0] == 'strips':
                    check_strips(toks[2], dmore, events, order)
                    continue
                if toks[0] == 'begun':
                    lhs, _, rhs = line.partition(' = ')
                    lt = lhs.split()
                    k = resolve_pos(lt[1:-1], events, order, dstart)
                    check_begun(k, lt[-1], rhs.split(), events, order)
                    continue
                if toks[0] == 'listing':
                    block = [l[4:].rstrip() for l in text_lines if l.startswith('    ')]
                    want = dlst.get(toks[1])
                    if not want:
                        raise ValueError('pdtview has no listing %r' % toks[1])
                    if not any(block[i:i + len(want)] == want for i in range(len(block))):
                        raise AssertionError('README.md has no block of the %d panel lines, '
                                             'from "%s"' % (len(want), want[0]))
                    continue
                op = ' ~ ' if ' ~ ' in line and toks[0] == 'line' else ' = '
                lhs, _, rhs = line.partition(op)
                lt = lhs.split()
                if toks[0] == 'code' and (lt[1] == 'each' or '..' in lt[1]):
                    check_code_all(lt[1:], rhs.split(), dev, events, order)
                    continue
                k = dstart if toks[0] == 'start' else resolve_pos(lt[1:], events, order, dstart)
                if toks[0] == 'start':
                    if k != int(rhs):
                        raise AssertionError('the lesson starts at %s' % k)
                    continue
                if k not in dev:
                    raise AssertionError('the viewer has no event %s' % k)
                listing, cl, text = dev[k]
                if toks[0] == 'line':
                    want = quoted(rhs)
                    if (op == ' = ' and text != want) or (op == ' ~ ' and want not in text):
                        raise AssertionError('the event line at %d reads "%s"' % (k, text))
                else:
                    r = rhs.split()
                    got = '%s %s' % (listing, cl if cl else '-')
                    if (len(r) == 1 and str(cl) != r[0]) or (len(r) == 2 and got != ' '.join(r)):
                        raise AssertionError('at %d the code panel lights %s line %s' % (
                            k, listing, cl if cl else '(none)'))
                continue
            if toks[0] == 'elapsed':
                check_elapsed(line, events, order)
                continue
            if ' = ' in line and toks[0] != 'sum':
                lhs, rhs = line.rsplit(' = ', 1)
                ltoks = lhs.split()
            if toks[0] == 'at':
                n = int(toks[1]) - 1 + DUMP_FIRST
                want = parse_fields(toks[3:])
                if n not in events:
                    raise AssertionError('the run has only %d events' % len(order))
                kind, fields, text = events[n]
                if not match(kind, fields, toks[2], want):
                    raise AssertionError('event %d is: %s' % (n + 1 - DUMP_FIRST, text.strip()))
            elif toks[0] == 'first':
                want = parse_fields(ltoks[2:])
                hits = [i for i in order if match(events[i][0], events[i][1], ltoks[1], want)]
                got = hits[0] + 1 - DUMP_FIRST if hits else None
                if got != int(rhs):
                    raise AssertionError('the first such event is the %s-th' % got)
            elif toks[0] == 'count':
                want = parse_fields(ltoks[2:])
                got = sum(1 for i in order if match(events[i][0], events[i][1], ltoks[1], want))
                if got != int(rhs):
                    raise AssertionError('counted %d' % got)
            elif toks[0] == 'sum':
                lhs2, op, val = line.rpartition(' > ') if ' > ' in line else line.rpartition(' = ')
                lt = lhs2.split()
                want = parse_fields(lt[3:])
                got = sum(int(events[i][1].get(lt[2], 0)) for i in order
                          if match(events[i][0], events[i][1], lt[1], want))
                if (op == ' > ' and not got > int(val)) or (op == ' = ' and got != int(val)):
                    raise AssertionError('the sum is %d' % got)
            elif toks[0] == 'max':
                want = parse_fields(ltoks[3:])
                vals = [int(events[i][1][ltoks[2]]) for i in order
                        if match(events[i][0], events[i][1], ltoks[1], want)
                        and ltoks[2] in events[i][1]]
                got = max(vals) if vals else None
                if got is None or got != int(rhs):
                    raise AssertionError('the largest %s is %s' % (ltoks[2], got))
            elif toks[0] == 'phases':
                want = rhs.split()
                ranks = sorted({events[i][1]['@rank'] for i in order}, key=int) \
                    if ltoks[1] == '*' else [ltoks[1]]
                for rk in ranks:
                    got = phases_begun(events, order, rk)
                    if got != want:
                        raise AssertionError('rank %s begins: %s' % (rk, ' '.join(got) or 'none')
                                             if rk != 'any' else 'the phases are: %s' % ' '.join(got))
            elif toks[0] == 'output-lines':
                if len(out) != int(rhs):
                    raise AssertionError('the program printed %d lines' % len(out))
            elif toks[0] == 'output-has':
                if toks[1:] not in out:
                    raise AssertionError('no such line in the output')
            elif toks[0] == 'output':
                got = [l[0] for l in out]
                if got != rhs.split():
                    raise AssertionError('the output is %s' % ' '.join(got))
            elif toks[0] == 'area2':
                a, b, c = (pts[int(t)] for t in ltoks[1:4])
                if area2(a, b, c) != int(rhs):
                    raise AssertionError('Area2 = %d' % area2(a, b, c))
            elif toks[0] == 'incircle':
                a, b, c, d = (pts[int(t)] for t in ltoks[1:5])
                got = incircle(a, b, c, d)
                sign = '+' if got > 0 else '-' if got < 0 else '0'
                if rhs not in (sign, str(got)):
                    raise AssertionError('incircle = %d' % got)
            elif toks[0] == 'output-same':
                other = run_data(toks[1])[2]
                if other != out:
                    raise AssertionError('the outputs of %s and %s differ' % (run, toks[1]))
            elif toks[0] == 'xrange':
                want = parse_fields(ltoks[2:])
                xs = [pts[int(events[i][1]['pt'])][0] for i in order
                      if match(events[i][0], events[i][1], ltoks[1], want)]
                got = '%d %d' % (min(xs), max(xs)) if xs else 'none'
                if got != rhs:
                    raise AssertionError('x runs from %s' % got.replace(' ', ' to '))
            elif toks[0] == 'squares':
                got = square_diagonals(pts, out)
                if got != rhs:
                    raise AssertionError('the unit squares are cut by: %s' % got)
            elif toks[0] == 'degree':
                d = sum(1 for t in out if ltoks[1] in t[:3])
                if d != int(rhs):
                    raise AssertionError('point %s is a corner of %d triangles' % (ltoks[1], d))
            elif toks[0] == 'hull-size':
                if hull_size(pts) != int(rhs):
                    raise AssertionError('the points have %d hull corners' % hull_size(pts))
            elif toks[0] == 'lift':
                x, y = pts[int(ltoks[1])]
                if x * x + y * y != int(rhs):
                    raise AssertionError('z = %d' % (x * x + y * y))
            else:
                raise ValueError('unknown check %r' % toks[0])
        except (AssertionError, ValueError, IndexError, KeyError, OSError) as e:
            bad += 1
            print('FAIL %s\n     %s' % (where, e))
    print('%s: %d checks, %d failed%s' % (os.path.basename(os.path.normpath(ldir)), nchecks, bad,
                                          ', %d skipped' % skipped if skipped else ''))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
