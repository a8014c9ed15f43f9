#!/usr/bin/env python3
"""Collects the runs of scripts/bench.sh (one folder per run: run.json, log.txt, time.txt and
the CLI's report.json) into results.json, docs/benchmarks.md and SVG convergence plots."""
import argparse
import json
import os
import re
import statistics

STEP_LINE = re.compile(
    r"node optimization \[(\w+)\] step (\d+): E = ([-+0-9.eE]+) \((accepted|rejected)\).*"
    r"fold-overs = (\d+), ([-+0-9.eE]+) s")


def load_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def peak_rss_mb(path):
    try:
        with open(path) as f:
            for line in f:
                if "Maximum resident set size" in line:
                    return int(line.split(":")[1]) / 1024.0
    except OSError:
        pass
    return None


def steps_from_log(path):
    """Progress lines of a run that was stopped before writing its steps (capped runs)."""
    steps = []
    try:
        with open(path, errors="replace") as f:
            for line in f:
                m = STEP_LINE.search(line)
                if m and m.group(1) != "initial":
                    steps.append({"phase": m.group(1), "step": int(m.group(2)),
                                  "E": float(m.group(3)), "accepted": m.group(4) == "accepted",
                                  "foldovers": int(m.group(5)), "time_s": float(m.group(6))})
                elif m:
                    steps.append({"phase": "initial", "step": 0, "E": float(m.group(3)),
                                  "accepted": True, "foldovers": int(m.group(5)),
                                  "time_s": float(m.group(6))})
    except OSError:
        pass
    return steps


def collect(runs_dir):
    runs = {}
    # In the order the runs ended (run.json is written last).
    names = sorted(os.listdir(runs_dir),
                   key=lambda n: os.path.getmtime(os.path.join(runs_dir, n, "run.json"))
                   if os.path.exists(os.path.join(runs_dir, n, "run.json")) else 0)
    for name in names:
        d = os.path.join(runs_dir, name)
        run = load_json(os.path.join(d, "run.json"))
        if run is None:
            continue
        run["report"] = load_json(os.path.join(d, "report.json"))
        run["peak_rss_mb"] = peak_rss_mb(os.path.join(d, "time.txt"))
        run["log_steps"] = steps_from_log(os.path.join(d, "log.txt"))
        run["capped"] = run["exit_code"] == 124 or (
            run["report"] is not None and run["report"].get("status") == "cancelled")
        runs[name] = run
    return runs


def fmt(x, digits=3):
    if x is None:
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int) or (isinstance(x, float) and x.is_integer() and abs(x) < 1e9):
        return str(int(x))
    if abs(x) >= 1000 or (abs(x) < 1e-3 and x != 0):
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def status(run):
    if run is None:
        return "not run"
    if run["capped"]:
        return f"capped ({run['cap_s']} s)"
    if run["exit_code"] != 0:
        return f"failed (exit {run['exit_code']})"
    return "ok"


def steps_of(run):
    rep = run["report"] if run else None
    if rep and rep.get("status") == "ok":
        return rep.get("steps", [])
    return [s for s in (run["log_steps"] if run else []) if s["phase"] != "initial"]


def energies(run):
    """E per step (initial first) for the convergence plots, accepted steps only."""
    rep = run["report"]
    series = []
    if rep and rep.get("status") == "ok" and "E_init" in rep:
        series.append(rep["E_init"])
        series += [s["E"] for s in rep.get("steps", []) if s.get("accepted")]
    else:
        series = [s["E"] for s in run["log_steps"] if s["accepted"]]
    return series


def table1_row(label, run, model_run=None):
    """model_run: a finished run on the same mesh, for faces and patches of a capped run."""
    rep = run["report"] if run else None
    ok = rep is not None and rep.get("status") == "ok"
    steps = steps_of(run)
    node = rep.get("node_optimization", {}) if ok else {}
    E_init = rep.get("E_init") if ok else (run["log_steps"][0]["E"] if run and run["log_steps"]
                                          else None)
    accepted = [s["E"] for s in (run["log_steps"] if run else []) if s["accepted"]]
    E_final = rep.get("E_final") if ok else (accepted[-1] if accepted else None)
    fold_before = node.get("foldovers_init") if ok else (
        run["log_steps"][0]["foldovers"] if run and run["log_steps"] else None)
    if ok and not node:
        fold_before = rep["metrics"]["foldovers"]
    fold_after = rep["metrics"]["foldovers"] if ok else None
    src = rep if ok else (model_run["report"] if model_run and model_run["report"] and
                          model_run["report"].get("status") == "ok" else None)
    faces = src["mesh"]["faces"] if src else None
    patches = src["layout"]["patches"] if src else None
    t = rep["timings_s"]["total"] if ok else (run["wall_s"] if run else None)
    return (f"| {label} | {fmt(faces)} | {fmt(patches)} | {fmt(t)} | {fmt(E_init)} | "
            f"{fmt(E_final)} | {fmt(fold_before)} → {fmt(fold_after)} | {len(steps)} | "
            f"{status(run)} |")


def median(xs):
    return statistics.median(xs) if xs else None


def svg_plot(title, series, path):
    """A small line chart: E (log scale) against the step number, one polyline per series."""
    w, h, ml, mr, mt, mb = 520, 300, 70, 150, 30, 40
    colors = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf"]
    import math
    pts = [(name, [e for e in es if e and e > 0]) for name, es in series if es]
    pts = [(n, es) for n, es in pts if es]
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
           f'font-family="sans-serif" font-size="11">',
           f'<rect width="{w}" height="{h}" fill="white"/>',
           f'<text x="{w / 2}" y="18" text-anchor="middle" font-size="13">{title}</text>']
    if pts:
        lo = min(min(es) for _, es in pts)
        hi = max(max(es) for _, es in pts)
        if hi <= lo:
            hi = lo * 1.1
        llo, lhi = math.log10(lo), math.log10(hi)
        pad = 0.05 * (lhi - llo)
        llo, lhi = llo - pad, lhi + pad
        n = max(len(es) for _, es in pts)
        pw, ph = w - ml - mr, h - mt - mb

        def X(i):
            return ml + pw * (i / max(n - 1, 1))

        def Y(e):
            return mt + ph * (1 - (math.log10(e) - llo) / (lhi - llo))
        out.append(f'<rect x="{ml}" y="{mt}" width="{pw}" height="{ph}" fill="none" '
                   f'stroke="#888"/>')
        for k in range(5):
            v = 10 ** (llo + (lhi - llo) * k / 4)
            out.append(f'<text x="{ml - 4}" y="{Y(v) + 4:.1f}" text-anchor="end">{v:.3g}</text>')
            out.append(f'<line x1="{ml}" x2="{ml + pw}" y1="{Y(v):.1f}" y2="{Y(v):.1f}" '
                       f'stroke="#eee"/>')
        for i in range(n):
            if n <= 12 or i % max(1, n // 10) == 0:
                out.append(f'<text x="{X(i):.1f}" y="{mt + ph + 14}" '
                           f'text-anchor="middle">{i}</text>')
        out.append(f'<text x="{ml + pw / 2}" y="{h - 6}" text-anchor="middle">accepted step '
                   f'(0 = initial layout)</text>')
        out.append(f'<text x="14" y="{mt + ph / 2}" text-anchor="middle" transform="rotate(-90 '
                   f'14 {mt + ph / 2})">E (log scale)</text>')
        for j, (name, es) in enumerate(pts):
            c = colors[j % len(colors)]
            poly = " ".join(f"{X(i):.1f},{Y(e):.1f}" for i, e in enumerate(es))
            out.append(f'<polyline points="{poly}" fill="none" stroke="{c}" stroke-width="2"/>')
            for i, e in enumerate(es):
                out.append(f'<circle cx="{X(i):.1f}" cy="{Y(e):.1f}" r="2.5" fill="{c}"/>')
            out.append(f'<text x="{ml + pw + 10}" y="{mt + 14 + 16 * j}" fill="{c}">{name}</text>')
    else:
        out.append(f'<text x="{w / 2}" y="{h / 2}" text-anchor="middle">no steps</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


# Separates the generated part of docs/benchmarks.md from the notes kept across runs.
NOTES_MARKER = ("<!-- Generated above (scripts/bench.sh); the notes below are written by hand "
                "and kept when the page is regenerated. -->")
# Before the marker existed, the hand-written notes began with this section.
FIRST_NOTES_HEADING = "## Cross-field stage cost"


def previous_notes(path):
    """The hand-written part of an existing page: what follows the marker (or, in a page from
    before the marker, the first notes heading on). Empty when there is no page. Raises when a
    page exists but neither is found, rather than dropping text nobody can regenerate."""
    try:
        with open(path) as f:
            text = f.read()
    except FileNotFoundError:
        return ""
    if NOTES_MARKER in text:
        return text.split(NOTES_MARKER, 1)[1].strip("\n")
    at = text.find("\n" + FIRST_NOTES_HEADING + "\n")
    if at >= 0:
        return text[at + 1:].strip("\n")
    if not text.strip():
        return ""
    raise SystemExit(f"make_report: {path} has no notes marker ({NOTES_MARKER!r}); "
                     "refusing to overwrite it (move it away to start a new page)")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", required=True)
    ap.add_argument("--machine", required=True)
    ap.add_argument("--json", required=True)
    ap.add_argument("--markdown", required=True)
    ap.add_argument("--svg-dir", required=True)
    args = ap.parse_args()
    machine = json.loads(args.machine)
    runs = collect(args.runs)
    models = []
    for name in runs:
        m = name.split(".")[0]
        if m not in models and m not in ("micro", "gradient_stats"):
            models.append(m)

    md = ["# Benchmarks", "",
          "Generated by `scripts/bench.sh` (issue #9); every number below comes from the run "
          "described here. Re-run the command to regenerate this page, `out/bench/results.json` "
          "and `docs/bench/*.svg`. Not part of the test suite.", "",
          "## Machine and run", "",
          f"- CPUs (`nproc --all`): {machine['nproc']}",
          f"- CPU model (`lscpu`): {machine['cpu']}",
          f"- Memory: {machine['memory']}",
          f"- Load average at the end of the run: {machine['load']} (the machine is shared: "
          "wall times include contention)",
          f"- Date (start of the run): {machine['date']}",
          f"- Git commit: {machine['commit']}",
          f"- Command: `{machine['command']}`",
          f"- Total runtime of the command: {machine['runtime_s']} s", "",
          "Layouts come from `quadsketch-cli import-quads` (spot onto itself, fandisk onto "
          "fandisk.off, the animals with `--refine 3`, joint on its own QuadWild quads) and "
          "`perturb --rings 2 --seed 1`; the ellipsoid is the bundled example "
          "(`ellipsoid_exact.layout.json` and the displaced sketch `ellipsoid.layout.json`, "
          "listed as its perturbed version). Each run is capped with `timeout`; a capped run is "
          "reported as such with the steps it printed before the cap.", ""]

    full = [m for m in models if m + ".opt" in runs]
    pert = [m for m in models if m not in full and m + ".perturbed.opt" in runs]
    none = [m for m in models if m not in full and m not in pert]
    md += ["Scope of this run: node optimization of both layouts and discrete relocation on "
           f"{', '.join(full) or 'no model'}; node optimization of the perturbed layout only on "
           f"{', '.join(pert) or 'no model'}; `--no-node-opt` only on "
           f"{', '.join(none) or 'no model'} (too large for the caps on 2 cores). Models not "
           "listed were not run (`--models` selects them).", ""]

    # Table 1 analogue.
    md += ["## Table 1 analogue: node optimization", "",
           "Continuous relocation with the estimator gradient (`optimize`), time = total "
           "command time (s). Fold-overs: before node optimization → in the final "
           "parameterization. A capped run shows the last accepted E it printed before the "
           "cap (its final fold-overs are unknown).", "",
           "| model | faces | patches | time (s) | E_init | E_final | fold-overs | steps | "
           "status |", "|---|---|---|---|---|---|---|---|---|"]
    for m in models:
        for suffix, label in ((".opt", m), (".align", m + " (no node opt)"),
                              (".perturbed.opt", m + " + perturb"),
                              (".perturbed.align", m + " + perturb (no node opt)")):
            if suffix == ".align" and (m + ".opt") in runs:
                continue
            run = runs.get(m + suffix)
            if run:
                md.append(table1_row(label, run, runs.get(m + ".align")))
    md.append("")

    # §9.1 aligned vs not.
    md += ["## §9.1: aligned vs unaligned (`--no-align`), same layout, `--no-node-opt`", "",
           "| model | E_confor aligned | E_confor `--no-align` | E_planar aligned | "
           "E_planar `--no-align` | E° aligned | E° `--no-align` | fold-overs | status |",
           "|---|---|---|---|---|---|---|---|---|"]
    for m in models:
        a, n = runs.get(m + ".align"), runs.get(m + ".noalign")
        if not a and not n:
            continue
        ma = a["report"]["metrics"] if a and a["report"] and "metrics" in a["report"] else {}
        mn = n["report"]["metrics"] if n and n["report"] and "metrics" in n["report"] else {}
        md.append(f"| {m} | {fmt(ma.get('E_confor'))} | {fmt(mn.get('E_confor'))} | "
                  f"{fmt(ma.get('E_planar'))} | {fmt(mn.get('E_planar'))} | "
                  f"{fmt(ma.get('E_angle_deg'))} | {fmt(mn.get('E_angle_deg'))} | "
                  f"{fmt(ma.get('foldovers'))} / {fmt(mn.get('foldovers'))} | "
                  f"{status(a)} / {status(n)} |")
    md.append("")

    # §6.3 continuous vs discrete.
    md += ["## §6.3: continuous vs discrete relocation (perturbed layouts)", "",
           "| model | E_init | E_final continuous | steps | time (s) | E_final discrete | "
           "steps | time (s) | discrete status |", "|---|---|---|---|---|---|---|---|---|"]
    for m in models:
        c, d = runs.get(m + ".perturbed.opt"), runs.get(m + ".perturbed.discrete")
        if not d:
            continue

        def final(r):
            if r and r["report"] and r["report"].get("status") == "ok":
                return r["report"]["E_final"]
            acc = [s["E"] for s in (r["log_steps"] if r else []) if s["accepted"]]
            return acc[-1] if acc else None

        def t(r):
            if r and r["report"] and r["report"].get("status") == "ok":
                return r["report"]["timings_s"]["total"]
            return r["wall_s"] if r else None
        rc = c["report"] if c and c["report"] and c["report"].get("status") == "ok" else {}
        E0 = rc.get("E_init") if rc else None
        dcap = ""
        if d["capped"]:
            dcap = " (last accepted E before the cap)" if final(d) else " (no step within the cap)"
        md.append(f"| {m} | {fmt(E0)} | {fmt(final(c))} | {len(steps_of(c))} | {fmt(t(c))} | "
                  f"{fmt(final(d))}{dcap} | {len(steps_of(d))} | {fmt(t(d))} | {status(d)} |")
    md.append("")

    # Speed against the limit.
    md += ["## Speed against the limit", "",
           "Median time of one node-optimization step (`steps[].time_s`, all steps of the "
           "`optimize` runs of the model) against one CHOLMOD numeric factorization + solve of "
           "the parameterization system (`param_factorize + param_solve` of the final solve). "
           "Peak memory: `/usr/bin/time -v` maximum resident set size over the model's runs.", "",
           "| model | unknowns | median step (s) | factorize + solve (s) | ratio | "
           "peak RSS (MB) |", "|---|---|---|---|---|---|"]
    speed = {}
    for m in models:
        step_times = []
        for suffix in (".opt", ".perturbed.opt"):
            step_times += [s["time_s"] for s in steps_of(runs.get(m + suffix))]
        fs, unknowns = None, None
        for suffix in (".opt", ".align", ".perturbed.opt"):
            r = runs.get(m + suffix)
            if r and r["report"] and r["report"].get("status") == "ok":
                ts = r["report"]["timings_s"]
                fs = ts["param_factorize"] + ts["param_solve"]
                unknowns = r["report"]["parameterization"]["unknowns"]
                break
        rss = [r["peak_rss_mb"] for n, r in runs.items()
               if n.split(".")[0] == m and r["peak_rss_mb"]]
        med = median(step_times)
        speed[m] = {"median_step_s": med, "factorize_solve_s": fs,
                    "ratio": med / fs if med and fs else None,
                    "peak_rss_mb": max(rss) if rss else None, "unknowns": unknowns}
        md.append(f"| {m} | {fmt(unknowns)} | {fmt(med)} | {fmt(fs)} | "
                  f"{fmt(speed[m]['ratio'])} | {fmt(speed[m]['peak_rss_mb'])} |")
    md.append("")

    # Gradient estimator statistics.
    gs = runs.get("gradient_stats")
    gstats = load_json(os.path.join(args.runs, "gradient_stats", "stats.json")) if gs else None
    md += ["## Gradient estimator vs exact gradient", ""]
    if gstats:
        md += ["`qs_bench_gradient`: the 1-ring estimator (`estimate_node_gradients`) against "
               "central finite differences that re-solve field and parameterization "
               "(`exact_node_gradients`), over all nodes of each layout.", "",
               "| layout | nodes | mean angle (°) | max angle (°) | mean \\|est\\|/\\|exact\\| | "
               "min ratio | max ratio | time (s) |", "|---|---|---|---|---|---|---|---|"]
        for row in gstats:
            md.append(f"| {row['name']} | {row['nodes']} | {fmt(row['mean_angle_deg'])} | "
                      f"{fmt(row['max_angle_deg'])} | {fmt(row['mean_ratio'], 5)} | "
                      f"{fmt(row['min_ratio'], 5)} | {fmt(row['max_ratio'], 5)} | "
                      f"{fmt(row['time_s'])} |")
    else:
        md.append(f"Not available in this run ({status(gs)}).")
    md.append("")

    # Micro-benchmarks.
    micro = load_json(os.path.join(args.runs, "micro", "micro.json"))
    md += ["## Micro-benchmarks (`qs_micro_bench`, Google Benchmark)", ""]
    if micro and micro.get("benchmarks"):
        md += ["Fixture: `cube_sphere(40)` (unit sphere, 19.2K faces, 6 patches, 8 valence-3 "
               "nodes). Wall and CPU time per iteration; on a loaded machine the CPU time is the "
               "more stable one. Debian's libbenchmark reports itself as a debug build; that "
               "does not affect the measured code.", "",
               "| kernel | wall / iteration | CPU / iteration | iterations | counters |",
               "|---|---|---|---|---|"]
        std_keys = {"name", "family_index", "per_family_instance_index", "run_name", "run_type",
                    "repetitions", "repetition_index", "threads", "iterations", "real_time",
                    "cpu_time", "time_unit", "aggregate_name", "aggregate_unit"}
        for b in micro["benchmarks"]:
            unit = b.get("time_unit", "ns")
            counters = ", ".join(f"{k} = {fmt(v)}" for k, v in b.items() if k not in std_keys)
            md.append(f"| {b['name']} | {fmt(b['real_time'])} {unit} | "
                      f"{fmt(b['cpu_time'])} {unit} | {b['iterations']} | {counters} |")
    else:
        md.append(f"Not available in this run ({status(runs.get('micro'))}).")
    md.append("")

    # Plots.
    os.makedirs(args.svg_dir, exist_ok=True)
    md += ["## Convergence", "",
           "E after each accepted node-optimization step (log scale), continuous relocation; "
           "discrete relocation where it ran.", ""]
    rel = os.path.relpath(args.svg_dir, os.path.dirname(os.path.abspath(args.markdown)))
    for m in models:
        series = []
        for suffix, label in ((".opt", "layout"), (".perturbed.opt", "perturbed"),
                              (".perturbed.discrete", "perturbed, discrete")):
            r = runs.get(m + suffix)
            if r:
                series.append((label, energies(r)))
        if not any(es for _, es in series):
            continue
        svg_plot(f"{m}: E per accepted step", series, os.path.join(args.svg_dir, m + ".svg"))
        md.append(f"![{m}]({rel}/{m}.svg)")
        md.append("")

    md += ["## Runs", "",
           "| run | status | wall (s) | peak RSS (MB) | command |", "|---|---|---|---|---|"]
    for n, r in runs.items():
        md.append(f"| {n} | {status(r)} | {fmt(r['wall_s'])} | {fmt(r['peak_rss_mb'])} | "
                  f"`{r['command'].replace(os.getcwd() + '/', '')}` |")
    md.append("")

    # The analysis below the marker (written by hand) is kept: only the part above it is this
    # run's. Written to a temporary file and renamed, so
    # that an interrupted run leaves the page as it was.
    kept = previous_notes(args.markdown)
    md += [NOTES_MARKER, ""]
    if kept:
        md.append(kept)
    tmp = args.markdown + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(md).rstrip("\n") + "\n")
    os.replace(tmp, args.markdown)
    results = {"machine": machine, "speed": speed,
               "runs": {n: {k: v for k, v in r.items() if k != "log_steps"}
                        for n, r in runs.items()},
               "gradient_stats": gstats, "micro": micro}
    with open(args.json, "w") as f:
        json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
