#!/usr/bin/env python3
"""Side by side: hindsight against the Reelay and RTAMT Python packages on the benchmark traces.

For every formula of the Rust benchmark (read from bench/src/cases.rs, so the two
never drift apart) this script

1. draws the benchmark trace (xorshift64* from the same seed as
   bench/src/lib.rs: timestamps = point index; p, q, r independent with
   probabilities 0.1, 0.1, 0.3), writes it as CSV and writes a .hspec
   (`state p: bool = false;` ...), then runs `hindsight replay SPEC TRACE`;
2. translates the formula for Reelay (`reelay.discrete_timed_monitor`, with
   `condense=False` so that every point has a verdict) and for RTAMT (past-time
   STL, `StlDiscreteTimeOnlineSpecification`, atoms as `p >= 0.5` over 0/1
   signals, verdict = robustness > 0), and runs each over the same trace in a
   subprocess (Reelay crashes the interpreter on some syntax errors);
3. checks that the verdicts agree with hindsight's at every point, and prints
   points per second for each tool and hindsight's ratio to it.

Where a tool cannot express a formula, the translation it was given instead
(an equivalent rewrite under discrete time with one point per tick) is
printed; where no translation exists or the verdicts disagree, the output says
so. Nothing is hidden or skipped silently.

This is a convenience, not the headline benchmark: both tools are driven from
Python, whose per-call overhead dominates their figures (Reelay's monitors are
C++ behind pybind11; RTAMT's discrete-time online monitors are pure Python, its
C++ backend is not in the PyPI wheel). hindsight's figures are the `try_step`
interpreter loop as `hindsight replay --quiet` reports it, and the whole
`hindsight replay` process (CSV parsing and output included). The generated
code is several times faster again: see `cargo bench -p hindsight-bench`.

Setup:
    pip install reelay rtamt
    cargo build --release -p hindsight     # the script builds it when missing

Usage:
    python3 scripts/compare_python.py [--points 1000000] [--rtamt-points 100000]
        [--only SUBSTRING] [--hindsight target/release/hindsight] [--keep DIR]

RTAMT runs on the first --rtamt-points points of the same trace (it takes
5-20 us per point); its verdicts are compared on that prefix.
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Mirrors bench/src/lib.rs: SEED, P_BELOW, Q_BELOW, R_BELOW, XorShift64Star.
SEED = 0x9E3779B97F4A7C15
MASK = (1 << 64) - 1
P_BELOW = MASK // 10
Q_BELOW = MASK // 10
R_BELOW = MASK // 10 * 3


def xorshift64star(seed):
    """The benchmark generator: yields 64-bit draws (bench/src/lib.rs `XorShift64Star`)."""
    x = seed or 1
    while True:
        x ^= x >> 12
        x ^= (x << 25) & MASK
        x ^= x >> 27
        yield (x * 0x2545F4914F6CDD1D) & MASK


def trace(points):
    """The benchmark trace: a list of (p, q, r) booleans, point i at time i."""
    rng = xorshift64star(SEED)
    return [(next(rng) < P_BELOW, next(rng) < Q_BELOW, next(rng) < R_BELOW) for _ in range(points)]


def bench_formulas():
    """The FORMULAS array of bench/src/cases.rs, in order."""
    path = os.path.join(ROOT, "bench", "src", "cases.rs")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    m = re.search(r"pub const FORMULAS: \[&str; \d+\] = \[(.*?)\];", text, re.S)
    if not m:
        sys.exit(f"{path}: no FORMULAS array")
    return [s.encode().decode("unicode_escape") for s in re.findall(r'"((?:[^"\\]|\\.)*)"', m.group(1))]


# ---------------------------------------------------------------------------
# A parser for the benchmark's Past-MTL subset (codegen/src/parse.rs has the
# real grammar): unary > S > && > || > -> (right) > <->.

class Unsupported(Exception):
    """A formula a tool cannot express."""


def parse(src):
    toks = re.findall(r"\{[^}]*\}|\[[^\]]*\]|<->|->|&&|\|\||[()!]|[A-Za-z_][A-Za-z_0-9]*", src)
    if "".join(toks) != re.sub(r"\s+", "", src):
        raise ValueError(f"cannot tokenise {src!r}")
    pos = [0]

    def peek():
        return toks[pos[0]] if pos[0] < len(toks) else None

    def take(expected=None):
        t = peek()
        if t is None or (expected is not None and t != expected):
            raise ValueError(f"{src!r}: expected {expected or 'a token'}, found {t!r}")
        pos[0] += 1
        return t

    def interval():
        t = peek()
        if t is None or not t.startswith("["):
            return 0, None
        take()
        lo, hi = t[1:-1].split(":")
        return int(lo or 0), (int(hi) if hi else None)

    def unary():
        t = take()
        if t in ("!", "not"):
            return ("not", unary())
        if t in ("P", "O", "once", "H", "historically"):
            lo, hi = interval()
            return ("P" if t in ("P", "O", "once") else "H", lo, hi, unary())
        if t in ("Y", "pre", "Z"):
            return ("Z" if t == "Z" else "Y", unary())
        if t == "(":
            e = iff()
            take(")")
            return e
        if t.startswith("{"):
            return ("atom", t[1:-1].strip())
        if t in ("true", "false"):
            return ("const", t == "true")
        raise ValueError(f"{src!r}: unexpected {t!r}")

    def since():
        e = unary()
        while peek() in ("S", "since"):
            take()
            lo, hi = interval()
            e = ("S", lo, hi, e, unary())
        return e

    def chain(sub, ops, name):
        def f():
            e = sub()
            while peek() in ops:
                take()
                e = (name, e, sub())
            return e
        return f

    conj = chain(since, ("&&", "and"), "and")
    disj = chain(conj, ("||", "or"), "or")

    def imp():
        e = disj()
        if peek() in ("->", "implies"):
            take()
            return ("imp", e, imp())
        return e

    iff = chain(imp, ("<->",), "iff")
    e = iff()
    if peek() is not None:
        raise ValueError(f"{src!r}: trailing {peek()!r}")
    return e


def interval_text(lo, hi, sep):
    return f"[{lo}{sep}{'' if hi is None else hi}]"


# Each tool's syntax for the boolean and one-step operators: `{a}`/`{b}` are the
# translated operands; a `str` under "Y"/"Z" that is not a template is why the tool
# cannot express the operator. `temporal` translates `P`, `H` and `S`.
REELAY = {
    "atom": "{{{name}}}",
    "true": "({p} or not {p})",
    "false": "({p} and not {p})",
    "const_note": "`true`/`false` are not Reelay keywords: written as `{p} or not {p}` / `{p} and not {p}`",
    "not": "not ({a})",
    "imp": "({a}) implies ({b})",
    "Y": "pre ({a})",
    "Z": Unsupported("Reelay has no weak yesterday `Z`"),
}
RTAMT = {
    "atom": "({name} >= 0.5)",
    "true": "(1 > 0)",
    "false": "(0 > 1)",
    "const_note": "`true`/`false` are not RTAMT keywords: written as `(1 > 0)` / `(0 > 1)`",
    "not": "not({a})",
    "imp": "({a}) -> ({b})",
    "Y": Unsupported("RTAMT's `prev` is true at the first point (that is `Z`, not `Y`)"),
    "Z": "prev({a})",
}


def translate(e, syn, temporal, notes):
    """`e` in the syntax `syn`, fully parenthesised (no reliance on the tool's precedence)."""
    k = e[0]
    r = lambda x: translate(x, syn, temporal, notes)
    if k == "atom":
        return syn["atom"].format(name=e[1])
    if k == "const":
        notes.add(syn["const_note"])
        return syn["true"] if e[1] else syn["false"]
    if k in ("not", "Y", "Z"):
        if isinstance(syn[k], Unsupported):
            raise syn[k]
        return syn[k].format(a=r(e[1]))
    if k in ("and", "or"):
        return f"({r(e[1])}) {k} ({r(e[2])})"
    if k == "imp":
        return syn["imp"].format(a=r(e[1]), b=r(e[2]))
    if k == "iff":
        a, b = r(e[1]), r(e[2])
        return f"({syn['imp'].format(a=a, b=b)}) and ({syn['imp'].format(a=b, b=a)})"
    if k in ("P", "H", "S"):
        return temporal(e, r, notes)
    raise ValueError(k)


def reelay_temporal(e, r, notes):
    """Reelay's `once`, `historically` and `since`, bounds as `[lo:hi]`."""
    k = e[0]
    bound = "" if (e[1], e[2]) == (0, None) else interval_text(e[1], e[2], ":")
    if k in ("P", "H"):
        word = "once" if k == "P" else "historically"
        return f"{word}{bound} ({r(e[3])})"
    return f"({r(e[3])}) since{bound} ({r(e[4])})"


def to_reelay(e, notes):
    """Reelay's Rye syntax."""
    return translate(e, REELAY, reelay_temporal, notes)


def rtamt_temporal(e, r, notes):
    """RTAMT's past operators; unbounded-above intervals rewritten."""
    k, lo, hi = e[0], e[1], e[2]
    if k in ("P", "H"):
        word = "once" if k == "P" else "historically"
        body = e[3] if k == "P" else ("not", e[3])
        if (lo, hi) == (0, None):
            return f"{word}({r(e[3])})"
        if hi is not None:
            return f"{word}[{lo}:{hi}]({r(e[3])})"
        notes.add("RTAMT has no `[a:]` bound: P[a:] f = once[a:a](once f), "
                  "H[a:] f = not once[a:a](once not f) (exact with one point per tick)")
        inner = f"once[{lo}:{lo}](once({r(body)}))"
        return inner if k == "P" else f"not({inner})"
    a, b = r(e[3]), r(e[4])
    if (lo, hi) == (0, None):
        return f"({a}) since ({b})"
    if hi is not None:
        return f"({a}) since[{lo}:{hi}] ({b})"
    notes.add("RTAMT has no `[a:]` bound: f S[a:] g = historically[0:a-1] f and "
              "once[a:a](f since g) (exact with one point per tick)")
    return f"(historically[0:{lo - 1}]({a})) and (once[{lo}:{lo}](({a}) since ({b})))"


def to_rtamt(e, notes):
    """RTAMT past-time STL over 0/1 float signals."""
    return translate(e, RTAMT, rtamt_temporal, notes)


# ---------------------------------------------------------------------------
# Workers: one tool, one formula, in a subprocess.

def worker(tool, formula, points, out_path):
    pts = trace(points)
    if tool == "reelay":
        import reelay
        m = reelay.discrete_timed_monitor(pattern=formula, condense=False)
        inputs = [{"p": p, "q": q, "r": r} for p, q, r in pts]
        update = m.update
        start = time.perf_counter()
        verdicts = [update(d)["value"] for d in inputs]
        elapsed = time.perf_counter() - start
    elif tool == "rtamt":
        import rtamt
        spec = rtamt.StlDiscreteTimeOnlineSpecification()
        for v in "pqr":
            spec.declare_var(v, "float")
        spec.declare_var("out", "float")
        spec.spec = "out = " + formula
        spec.parse()
        inputs = [[("p", float(p)), ("q", float(q)), ("r", float(r))] for p, q, r in pts]
        update = spec.update
        start = time.perf_counter()
        rob = [update(t, x) for t, x in enumerate(inputs)]
        elapsed = time.perf_counter() - start
        if any(x == 0 for x in rob):
            raise SystemExit("robustness 0: verdict undefined")
        verdicts = [x > 0 for x in rob]
    else:
        raise SystemExit(f"unknown tool {tool}")
    with open(out_path, "w") as f:
        f.write("".join("1" if v else "0" for v in verdicts))
    print(json.dumps({"seconds": elapsed, "points": points}))


def run_worker(tool, formula, points, tmp, timeout):
    out = os.path.join(tmp, f"{tool}.verdicts")
    if os.path.exists(out):
        os.remove(out)
    cmd = [sys.executable, os.path.abspath(__file__), "--worker", tool, formula, str(points), out]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, f"timed out after {timeout} s"
    if p.returncode != 0:
        lines = [l for l in (p.stderr + p.stdout).strip().splitlines() if l.strip()]
        why = lines[-1] if lines else ""
        return None, f"failed (exit {p.returncode}{', signal' if p.returncode < 0 else ''}): {why[:160]}"
    info = json.loads(p.stdout.strip().splitlines()[-1])
    with open(out) as f:
        verdicts = f.read()
    return (verdicts, info["seconds"]), None


# ---------------------------------------------------------------------------

def hindsight_run(binary, formula, csv_path, tmp):
    spec = os.path.join(tmp, "bench.hspec")
    with open(spec, "w") as f:
        f.write("unit 1s;\nstate p: bool = false;\nstate q: bool = false;\n"
                f"state r: bool = false;\nproperty f = {formula};\n")
    start = time.perf_counter()
    p = subprocess.run([binary, "replay", spec, csv_path], capture_output=True, text=True)
    wall = time.perf_counter() - start
    if p.returncode != 0:
        raise SystemExit(f"hindsight replay failed on {formula}: {p.stderr.strip()}")
    rows = p.stdout.splitlines()[1:]
    verdicts = "".join("1" if row.endswith(",true") else "0" for row in rows)
    q = subprocess.run([binary, "replay", "--quiet", spec, csv_path], capture_output=True, text=True)
    m = re.search(r"([\d.]+) ns per point, (\d+) bytes", q.stderr)
    if q.returncode != 0 or not m:
        raise SystemExit(f"hindsight replay --quiet: unexpected output {q.stderr!r}")
    return verdicts, float(m.group(1)), wall, int(m.group(2))


def compare(ours, theirs):
    """None when equal on theirs' length, else (first index, count) of disagreements."""
    n = len(theirs)
    bad = [i for i in range(n) if ours[i] != theirs[i]]
    return (bad[0], len(bad)) if bad else None


def rate(points, seconds):
    return points / seconds if seconds > 0 else float("inf")


def human(x):
    for unit, div in (("G", 1e9), ("M", 1e6), ("k", 1e3)):
        if x >= div:
            return f"{x / div:.2f}{unit}"
    return f"{x:.0f}"


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        _, _, tool, formula, points, out = sys.argv
        worker(tool, formula, int(points), out)
        return
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--rtamt-points", type=int, default=100_000)
    ap.add_argument("--only", help="run only formulas containing this text")
    ap.add_argument("--hindsight", default=os.path.join(ROOT, "target", "release", "hindsight"))
    ap.add_argument("--timeout", type=float, default=600, help="seconds per tool and formula")
    ap.add_argument("--keep", help="write the trace, spec and verdicts here instead of a temp dir")
    args = ap.parse_args()
    if args.points <= 0 or args.rtamt_points <= 0:
        sys.exit("--points and --rtamt-points must be positive")
    rt_points = min(args.rtamt_points, args.points)

    if not os.path.exists(args.hindsight):
        print(f"building {args.hindsight} (cargo build --release -p hindsight)", flush=True)
        subprocess.run(["cargo", "build", "--release", "-q", "-p", "hindsight"], cwd=ROOT, check=True)

    tmp = args.keep or tempfile.mkdtemp(prefix="hindsight-compare-")
    os.makedirs(tmp, exist_ok=True)
    pts = trace(args.points)
    csv_path = os.path.join(tmp, "trace.csv")
    with open(csv_path, "w") as f:
        f.write("time,p,q,r\n")
        f.writelines(f"{i},{int(p)},{int(q)},{int(r)}\n" for i, (p, q, r) in enumerate(pts))
    counts = [sum(x[k] for x in pts) for k in range(3)]
    print(f"trace: {args.points} points (RTAMT: the first {rt_points}), seed {SEED:#x}, "
          f"timestamps = index; p {counts[0]}, q {counts[1]}, r {counts[2]} true")
    print(f"machine: {os.cpu_count()} CPUs visible; Python {sys.version.split()[0]}\n")

    formulas = [f for f in bench_formulas() if not args.only or args.only in f]
    rows, notes_out = [], []
    for formula in formulas:
        print(f"== {formula}", flush=True)
        ours, loop_ns, wall, state = hindsight_run(args.hindsight, formula, csv_path, tmp)
        if len(ours) != args.points:
            sys.exit(f"hindsight gave {len(ours)} verdicts for {args.points} points")
        row = {"formula": formula, "loop": 1e9 / loop_ns, "wall": rate(args.points, wall), "state": state}
        ast = parse(formula)
        for tool, translate, n in (("reelay", to_reelay, args.points), ("rtamt", to_rtamt, rt_points)):
            notes = set()
            try:
                text = translate(ast, notes)
            except Unsupported as e:
                row[tool] = None
                print(f"   {tool}: cannot express it: {e}")
                notes_out.append(f"{formula}: {tool} cannot express it: {e}")
                continue
            print(f"   {tool}: {text}")
            for note in sorted(notes):
                print(f"      ({note})")
            result, err = run_worker(tool, text, n, tmp, args.timeout)
            if err:
                row[tool] = None
                print(f"   {tool}: {err}")
                notes_out.append(f"{formula}: {tool} {err}")
                continue
            verdicts, seconds = result
            diff = compare(ours, verdicts)
            agree = "yes" if diff is None else f"NO: {diff[1]} points, first {diff[0]}"
            if diff is not None:
                i = diff[0]
                notes_out.append(f"{formula}: {tool} disagrees at {diff[1]} of {n} points; first at point {i} "
                                 f"(hindsight {ours[i] == '1'}, {tool} {verdicts[i] == '1'})")
            row[tool] = (rate(n, seconds), agree)
            print(f"   {tool}: {human(rate(n, seconds))} points/s over {n} points, agrees: {agree}", flush=True)
        rows.append(row)

    print("\npoints per second (higher is better); ratio = hindsight try_step loop / tool; "
          "agree = same verdict at every point\n")
    head = ("formula", "state B", "hs loop", "hs replay", "reelay", "ratio", "agree", "rtamt", "ratio", "agree")
    widths = (42, 8, 9, 9, 9, 8, 6, 9, 8, 6)
    print("| " + " | ".join(h.ljust(w) if i == 0 else h.rjust(w) for i, (h, w) in enumerate(zip(head, widths))) + " |")
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for row in rows:
        cells = [f"`{row['formula']}`", str(row["state"]), human(row["loop"]), human(row["wall"])]
        for tool in ("reelay", "rtamt"):
            if row[tool] is None:
                cells += ["-", "-", "n/a"]
            else:
                r, agree = row[tool]
                cells += [human(r), f"{row['loop'] / r:.0f}x", "yes" if agree == "yes" else "NO"]
        print("| " + " | ".join(c.ljust(w) if i == 0 else c.rjust(w) for i, (c, w) in enumerate(zip(cells, widths))) + " |")
    if notes_out:
        print("\nnot expressible, failed or disagreeing:")
        for n in notes_out:
            print(f"  - {n}")
    else:
        print("\nevery formula was run by every tool, and every verdict agreed")
    if not args.keep:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
