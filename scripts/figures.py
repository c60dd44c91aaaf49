#!/usr/bin/python3
"""Regenerates the figures in README.md and docs/*.md that come from commands.

Each figure is a Markdown block between two marker comments,

    <!-- figures:NAME begin: scripts/figures.sh PART -->
    ...
    <!-- figures:NAME end -->

and running a part replaces the block in place (the markers stay). Normally
run through scripts/figures.sh, which builds skybake first:

    /usr/bin/python3 scripts/figures.py SKYBAKE PART...

Parts (figure blocks, the page, the commands run):

  sizes    file-sizes (docs/files.md): `skybake bake earth` and
           `skybake bake earth --half` (--json), `skybake convert --half --json`
           on each float EXR table; a few seconds
  orders   orders-tail (docs/accuracy.md): `skybake bake earth --orders N
           --json` for N = 1..6 and auto, and `--orders 4 --no-tail`; under a minute
  cli      presets, bake-defaults (docs/cli.md): `skybake presets --json`,
           `skybake bake --help`; instant
  scenes   scenes (examples/scenes/README.md): `skybake bake earth --scene
           SCENE --compare-full --json` for each example scene, RUNS times
           (default 5, the times' medians); about two minutes
  stress   stress (docs/stability.md): `skybake stress --json`; about half a minute
  bench    bench (docs/benchmark.md): scripts/bench.sh (RUNS=5: about 7 minutes)
  report   report (docs/accuracy.md), docs/images/report/, and the report's
           colour section as colour-errors (docs/colour.md, README.md):
           `/usr/bin/time -v skybake report earth -o build/figures/report`
           (a few minutes)
  runtime-cost
           runtime-cost (docs/runtime_cost.md): `skybake bake earth` into
           build/figures/runtime-cost/earth, the peer runtime installed by
           tests/runtime_cost/install_peer.mjs, then `skybake_runtime_cost
           --size 1024 --runs 5` on them (SIZE and RUNS override; about 10
           minutes); the tool is $SKYBAKE_RUNTIME_COST, else
           build/tests/skybake_runtime_cost

bench, report, scenes and runtime-cost time the machine: run them with nothing else running.
"""
import json
import os
import pathlib
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
WORK = pathlib.Path("build") / "figures"  # relative to ROOT, the working directory
TABLES = ["transmittance", "irradiance", "scattering", "single_mie_scattering"]


def run(args, **kwargs):
    return subprocess.run(args, check=True, capture_output=True, text=True, cwd=ROOT, **kwargs).stdout


def replace_block(page, name, part, text):
    """Replaces the text between figures:NAME's markers in page (relative to the root)."""
    path = ROOT / page
    source = path.read_text()
    pattern = re.compile(r"(<!-- figures:%s begin[^>]*-->\n).*?(<!-- figures:%s end -->)" % (re.escape(name),
                                                                                              re.escape(name)),
                         re.S)
    if not pattern.search(source):
        sys.exit(f"figures: no figures:{name} markers in {page}")
    begin = f"<!-- figures:{name} begin: scripts/figures.sh {part} -->\n"
    updated = pattern.sub(lambda m: begin + text.rstrip("\n") + "\n" + m.group(2), source, count=1)
    path.write_text(updated)
    print(f"figures: {page}: figures:{name}", file=sys.stderr)


def thousands(n):
    return f"{n:,}".replace(",", " ")


def bake_json(skybake, directory, *options):
    shutil.rmtree(directory, ignore_errors=True)
    return json.loads(run([skybake, "bake", "earth", "-o", str(directory), "-q", "--json", *options]))


def sizes(skybake):
    full = bake_json(skybake, WORK / "sizes" / "float")
    half = bake_json(skybake, WORK / "sizes" / "half", "--half")
    size = lambda report, name: next(f["bytes"] for f in report["files"] if f["file"] == name)
    rows = []
    for table in TABLES:
        dims = full["tables"][table]
        texture = "×".join(str(d) for d in dims)
        conversion = json.loads(run([skybake, "convert", str(WORK / "sizes" / "float" / f"{table}.exr"),
                                     str(WORK / "sizes" / f"{table}.half.exr"), "--half", "--json"]))
        error = conversion["half_error"]
        values = len(conversion["channels"])
        for d in dims:
            values *= d
        rows.append(f"| {table} | {texture} | {thousands(size(full, table + '.exr'))} | "
                    f"{thousands(size(half, table + '.exr'))} | {thousands(size(full, table + '.ktx2'))} | "
                    f"{thousands(size(half, table + '.ktx2'))} | {error['max_relative_error']:.2e} | "
                    f"{thousands(error['below_floor'])} ({thousands(error['flushed_to_zero'])}) of {thousands(values)} |")
    total = lambda report: sum(f["bytes"] for f in report["files"] if f["table"])
    text = ("| table | size | EXR float | EXR half | KTX2 float | KTX2 half | half: max relative error (|v| ≥ 2⁻¹⁴) "
            "| half: non-zero values < 2⁻¹⁴ (flushed to 0) of all values |\n"
            "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |\n" + "\n".join(rows) + "\n\n"
            f"All table files: {thousands(total(full))} bytes in float, {thousands(total(half))} bytes in half.")
    replace_block("docs/files.md", "file-sizes", "sizes", text)

    # The README's KTX2 tables stored as is and Zstandard-supercompressed.
    ktx2_bytes = lambda report: sum(f["bytes"] for f in report["files"] if f["file"].endswith(".ktx2"))
    lines = ["| KTX2 tables | stored as is | zstd (level 3) | zstd:19 |", "| --- | ---: | ---: | ---: |"]
    for label, precision, stored in (("float", [], full), ("half (`--half`)", ["--half"], half)):
        cells = [f"{ktx2_bytes(stored) / 1e6:.1f} MB"]
        for level in ("zstd", "zstd:19"):
            packed = ktx2_bytes(bake_json(skybake, WORK / "sizes" / "zstd", "--format", "ktx2", "--runtime", "none",
                                          "--ktx2-supercompression", level, *precision))
            cells.append(f"{packed / 1e6:.1f} MB (−{round(100 * (1 - packed / ktx2_bytes(stored)))} %)")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    replace_block("README.md", "ktx2-zstd", "sizes", "\n".join(lines))


def orders(skybake):
    runs = [(str(n), ["--orders", str(n)]) for n in range(1, 7)]
    runs.insert(4, ("4, `--no-tail`", ["--orders", "4", "--no-tail"]))
    runs.append(("auto", ["--orders", "auto"]))
    rows = []
    for label, options in runs:
        r = bake_json(skybake, WORK / "orders", *options)
        remaining = "—" if r["remaining_error"] is None else f"{r['remaining_error']:.2e}"
        tail = f"{100 * r['extrapolated_tail']:.2f}%" if r["extrapolated_tail"] > 0 else "none"
        ratio = f"{r['order_ratio']:.4f}" if r["orders_used"] >= 3 else "—"  # 0 until order 3
        rows.append(f"| {label} | {r['orders_used']} | {ratio} | {tail} | {remaining} |")
    shutil.rmtree(WORK / "orders", ignore_errors=True)
    text = ("| `--orders` | orders computed | ratio q of the last two | extrapolated tail (of the table) "
            "| estimated remaining error |\n| --- | ---: | ---: | ---: | ---: |\n" + "\n".join(rows))
    replace_block("docs/accuracy.md", "orders-tail", "orders", text)


def bake_defaults(help_text):
    """(option, default) for every option of `skybake bake --help` that states one."""
    # CLI11 moves a description to the next line when the option column is full.
    lines = []
    for line in help_text.splitlines():
        if lines and re.match(r"\s{20,}\S", line) and not line.lstrip().startswith("-"):
            lines[-1] += " " + line.strip()
        else:
            lines.append(line)
    defaults = []
    for line in lines:
        # TYPE, TYPE:{choices}, =DEFAULT, x COUNT
        m = re.match(r"\s+(?:-\w,)?(--[\w-]+)(?: (\w+)(?::\{[^}]*\})?)?(?:=(\S+))?(?: x (\d))?(?:\s+(.*))?$", line)
        if not m:
            continue
        option, value, description = m.group(1), m.group(3), m.group(5) or ""
        if value is None:
            d = re.search(r"\(default ([^;)]*)", description)
            value = d.group(1) if d else None
        if value is not None and option != "--help":
            defaults.append((option, value.replace("[", "").replace("]", "")))
    return defaults


def cli(skybake):
    presets = json.loads(run([skybake, "presets", "--json"]))
    text = "| preset | description |\n| --- | --- |\n" + "\n".join(
        f"| `{p['name']}` | {p['description']} |" for p in presets)
    replace_block("docs/cli.md", "presets", "cli", text)
    defaults = bake_defaults(run([skybake, "bake", "--help"]))
    text = "| option | default |\n| --- | --- |\n" + "\n".join(f"| `{o}` | `{v}` |" for o, v in defaults)
    replace_block("docs/cli.md", "bake-defaults", "cli", text)


SCENES = ["ground-daytime-game", "sunset-cinematic", "flight-simulator", "space-to-ground"]


def scenes(skybake):
    runs = int(os.environ.get("RUNS", "5"))
    rows = []
    for name in SCENES:
        comparisons = []
        for _ in range(runs):
            out = bake_json(skybake, WORK / "scenes" / name, "--scene", f"examples/scenes/{name}.toml",
                            "--compare-full")
            comparisons.append(out["scene"]["comparison"])
        median = lambda key: sorted(c[key] for c in comparisons)[runs // 2]
        c = comparisons[0]
        scene_seconds, full_seconds = median("scene_bake_seconds"), median("full_bake_seconds")
        errors = c["accuracy"]["errors"]["radiance"]
        error = lambda e: (f"{100 * e['mean_relative']:.2f} / {100 * e['rms_relative']:.2f} / "
                           f"{100 * e['max_relative']:.1f}%")
        rows.append(f"| {name} | {100 * c['scene_table_bytes'] / c['full_table_bytes']:.1f}% | "
                    f"{scene_seconds:.2f} s of {full_seconds:.2f} s ({100 * scene_seconds / full_seconds:.0f}%) | "
                    f"{c['accuracy']['cases']} | {error(errors['scene'])} | {error(errors['full'])} |")
    text = (f"`scripts/figures.sh scenes` (`skybake bake earth --scene SCENE --compare-full`, bake times the "
            f"medians of {runs} runs, {os.cpu_count()} cores):\n\n"
            "| scene | table bytes | bake time | cases | scene error | full bake error |\n"
            "| --- | ---: | --- | ---: | --- | --- |\n" + "\n".join(rows))
    replace_block("examples/scenes/README.md", "scenes", "scenes", text)


def bench(skybake):
    env = dict(os.environ, RUNS=os.environ.get("RUNS", "5"))
    text = run([str(ROOT / "scripts" / "bench.sh")], env=env)
    replace_block("docs/benchmark.md", "bench", "bench", f"`RUNS={env['RUNS']} scripts/bench.sh`:\n\n" + text)


def report(skybake):
    out = WORK / "report"
    shutil.rmtree(out, ignore_errors=True)
    load = os.getloadavg()[0]  # other work on the machine slows the timed bakes
    with tempfile.NamedTemporaryFile("r", suffix=".time") as timing:
        tables = run(["/usr/bin/time", "-v", "-o", timing.name, skybake, "report", "earth", "-o", str(out)])
        usage = timing.read()
    field = lambda name: re.search(re.escape(name) + r": (.*)", usage).group(1).strip()
    wall = field("Elapsed (wall clock) time (h:mm:ss or m:ss)")
    cpu = float(field("User time (seconds)")) + float(field("System time (seconds)"))
    peak = int(field("Maximum resident set size (kbytes)")) / 1024
    for name in ["error_vs_bake_time.png", "error_vs_bake_time.svg"]:
        shutil.copy(out / name, ROOT / "docs" / "images" / "report" / name)
    text = (f"`skybake report earth -o build/figures/report`: {wall} wall time, {cpu:.0f} s CPU, peak resident "
            f"memory {peak:.0f} MiB (`/usr/bin/time -v`), {os.cpu_count()} cores, load average {load:.1f} at the "
            f"start (0 on an idle machine; more slows the bake times).\n\n" + tables)
    replace_block("docs/accuracy.md", "report", "report", text)
    # The report's colour section, its table and the line under it, also in docs/colour.md and the README.
    colour = tables[tables.index("| case group |", tables.index("### Colour")):].strip() + "\n"
    replace_block("docs/colour.md", "colour-errors", "report", colour)
    replace_block("README.md", "colour-errors", "report", colour)


# What each atmosphere of bake/stress_set.cpp pushes to an extreme.
STRESSES = {
    "optical-depth-10": "τ = 10 (blue), albedo 0.99, HG g = 0.7, 10 km slab",
    "optical-depth-100": "τ = 100, albedo 0.9, Rayleigh phase, H = 2 km",
    "optical-depth-1000": "τ = 1000, albedo 0.8, isotropic, 10 km slab",
    "albedo-0.999999": "albedo 0.999999, τ = 1, ground 0.3",
    "forward-g-0.999": "Earth air + HG haze g = +0.999",
    "backward-g-0.999": "Earth air + HG haze g = −0.999",
    "tiny-planet-1km": "R = 1 km, 500 m of air",
    "giant-planet-100000km": "R = 100,000 km, 200 km of air",
    "thin-shell-1m": "1 m atmosphere on Earth's radius, τ = 0.1",
    "thick-shell-10R": "atmosphere 10 planet radii thick",
    "vacuum-gap": "haze at 0–2 km and 20–60 km, vacuum between",
    "no-constituents": "vacuum",
    "absorption-only": "uniform absorber, τ = 1.2",
    "black-ground": "Earth air, ground albedo 0",
    "white-ground": "non-absorbing Earth air, ground albedo 1, μs_min = −1",
    "heavy-fog": "preset, haze 0.01 m⁻¹",
}


def stress(skybake):
    start, before = time.monotonic(), resource.getrusage(resource.RUSAGE_CHILDREN)
    results = json.loads(run([skybake, "stress", "--json"]))
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall, cpu = time.monotonic() - start, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    presets = {p["name"] for p in json.loads(run([skybake, "presets", "--json"]))}
    delta = lambda v: "0" if v == 0 else f"{v:.2g}"
    rows = []
    for r in results:
        name = r["atmosphere"]
        what = STRESSES.get(name, "preset" if name in presets else "")
        energy = " ".join(f"{e:.4f}" if name == "white-ground" else f"{e:.3f}" for e in r["energy_out"])
        if name == "white-ground":
            energy = f"**{energy}**"
        rows.append(f"| `{name}` | {what} | {r['orders_used']} | {delta(r['remaining_error'])} | {energy} | "
                    f"{delta(r['largest_transmittance_increase'])}, {delta(r['largest_direction_difference'])} |")
    violations = sum(r["violations"] for r in results)
    unbalanced = [r["atmosphere"] for r in results if not r.get("energy_balanced", True)]
    text = (f"`skybake stress --json`: {len(results)} atmospheres, {violations} invariant violations, "
            f"energy balanced in {'all' if not unbalanced else 'all but ' + ', '.join(unbalanced)}; "
            f"{wall:.1f} s wall, {cpu:.1f} s CPU on {os.cpu_count()} cores (load average "
            f"{os.getloadavg()[0]:.1f} at the end).\n\n"
            "| atmosphere | stresses | orders | remaining | energy out | ΔT along, ΔT reversed |\n"
            "| --- | --- | ---: | ---: | --- | --- |\n" + "\n".join(rows))
    replace_block("docs/stability.md", "stress", "stress", text)


def runtime_cost(skybake):
    work = WORK / "runtime-cost"
    luts = work / "earth"
    run([skybake, "bake", "earth", "-o", str(luts), "-q"])  # at once when the set is already there
    peer = run(["node", "tests/runtime_cost/install_peer.mjs", "--work-dir", str(work / "npm")]).strip()
    tool = os.environ.get("SKYBAKE_RUNTIME_COST", "build/tests/skybake_runtime_cost")
    size, runs = os.environ.get("SIZE", "1024"), os.environ.get("RUNS", "5")
    load = os.getloadavg()[0]
    start = time.monotonic()
    # Its progress and any failure on standard error, as it goes.
    subprocess.run([tool, "--luts", str(luts), "--peer", peer, "--size", size, "--runs", runs, "--json",
                    str(work / "cost.json"), "--markdown", str(work / "cost.md")],
                   check=True, stdout=subprocess.DEVNULL, cwd=ROOT)
    wall = time.monotonic() - start
    # Which runtime was measured: the commit, and whether shaders_runtime/ differed from it.
    try:
        commit = run(["git", "rev-parse", "--short", "HEAD"]).strip()
        edited = run(["git", "status", "--porcelain", "--", "shaders_runtime"]).strip()
        runtime = f"the runtime of commit {commit}" + (" with uncommitted changes in shaders_runtime/" if edited else "")
    except (subprocess.CalledProcessError, FileNotFoundError):
        runtime = "the runtime of a tree outside git"
    text = (f"`scripts/figures.sh runtime-cost` (`skybake_runtime_cost --luts build/figures/runtime-cost/earth --peer "
            f"… --size {size} --runs {runs}`) on {runtime}: {wall / 60:.1f} minutes, {os.cpu_count()} cores, load "
            f"average {load:.1f} at the start (0 on an idle machine; more makes the times noisier, the ratios less so, "
            f"since the runs alternate).\n\n" + (work / "cost.md").read_text())
    replace_block("docs/runtime_cost.md", "runtime-cost", "runtime-cost", text)


PARTS = {"sizes": sizes, "orders": orders, "cli": cli, "scenes": scenes, "stress": stress, "bench": bench,
         "report": report,
         "runtime-cost": runtime_cost}


def main():
    if len(sys.argv) < 3 or any(p not in PARTS for p in sys.argv[2:]):
        sys.exit(__doc__)
    skybake = sys.argv[1]
    os.chdir(ROOT)
    WORK.mkdir(parents=True, exist_ok=True)
    for part in sys.argv[2:]:
        PARTS[part](skybake)


if __name__ == "__main__":
    main()
