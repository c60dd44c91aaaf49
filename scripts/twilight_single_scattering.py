#!/usr/bin/python3
"""Single scattering of a bake against the reference's, from low sun to deep twilight.

Bakes earth with one order and no tail, answers a grid of views (zenith
0/45/80/85/88 degrees, azimuth 0/90/180 from the sun, camera at 0, 1 and 10 km)
for sun zenith angles from 80 to 100 degrees with `skybake eval`, and with
`skybake reference --max-order 1`, whose single scattering converges in
twilight (docs/reference.md, "Twilight"); prints per sun range the RMS,
median and largest relative error over the cases and the three wavelengths,
then the same over the values the eye could see, those whose exact value is
at least 1e-9 W m^-2 sr^-1 nm^-1 (a third of the moonless night sky at
550 nm, about 2e-4 cd/m^2); and, where the exact single scattering is 0
(the view ray wholly in the Earth's shadow), the largest value the tables
give:

    /usr/bin/python3 scripts/twilight_single_scattering.py build/cli/skybake [PATHS [BAKE OPTION ...]]

PATHS (default 4096) per wavelength: the reference's relative standard error
is then about 1e-3 (about 20 s in all on 2 cores). Further arguments go to
the bake, e.g. `--scattering-size 32 128 128 8` to see what four times the
mu_s texels would do.

With --horizon in place of PATHS, the views are the horizon band instead
(reference/cases/earth_horizon.csv: 87-93 degrees from the zenith, sun 85-96
degrees, 0 m to 10 km), against its committed single scattering
(earth_horizon_single_reference.csv), per sun range 85-90 and 91-96:

    /usr/bin/python3 scripts/twilight_single_scattering.py build/cli/skybake --horizon [BAKE OPTION ...]
"""
import csv
import io
import math
import pathlib
import statistics
import subprocess
import sys
import tempfile

SUNS = [80, 84, 86, 88, 89, 90, 91, 92, 93, 94, 95, 96, 97, 98, 99, 100]
VIEWS = [0, 45, 80, 85, 88]
AZIMUTHS = [0, 90, 180]
ALTITUDES = [0, 1000, 10000]
CHANNELS = ["680nm", "550nm", "440nm"]
VISIBLE = 1e-9
RANGES = [("sun 80-90", 80, 90), ("sun 90-96", 90, 96), ("sun 96-100", 96, 100)]
HORIZON_RANGES = [("sun 85-90", 85, 90), ("sun 91-96", 90, 96)]  # whole degrees: 91-96 is (90, 96]
CASES = pathlib.Path(__file__).resolve().parent.parent / "reference" / "cases"


def run(*arguments):
    return subprocess.run(list(arguments), capture_output=True, text=True, check=True).stdout


def main():
    skybake = sys.argv[1]
    paths = sys.argv[2] if len(sys.argv) > 2 else "4096"
    bake_options = sys.argv[3:]
    with tempfile.TemporaryDirectory() as work:
        if paths == "--horizon":
            queries = str(CASES / "earth_horizon.csv")
            with open(CASES / "earth_horizon_single_reference.csv") as f:
                exact = list(csv.DictReader(f))
            ranges = HORIZON_RANGES
        else:
            queries = f"{work}/queries.csv"
            with open(queries, "w") as f:
                f.write("altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,distance_m,normal_zenith_deg\n")
                for sun in SUNS:
                    for view in VIEWS:
                        for azimuth in AZIMUTHS:
                            for altitude in ALTITUDES:
                                f.write(f"{altitude},{view},{sun},{azimuth},,\n")
            exact = list(csv.DictReader(io.StringIO(
                run(skybake, "reference", "earth", "--in", queries, "--paths", paths, "--max-order", "1", "-q"))))
            ranges = RANGES
        run(skybake, "bake", "earth", "--orders", "1", "--no-tail", "-o", f"{work}/set", "-q", *bake_options)
        table = list(csv.DictReader(io.StringIO(run(skybake, "eval", f"{work}/set", "--in", queries))))
        compare(table, exact, ranges)


def compare(table, exact, ranges):
    for name, low, high in ranges:
        errors, visible, dark = [], [], []
        for t, e in zip(table, exact):
            sun = float(e["sun_zenith_deg"])
            if not (low <= sun <= high) or (sun == low and low != ranges[0][1]):
                continue
            for c in CHANNELS:
                baked, truth = float(t["radiance_" + c]), float(e["radiance_" + c])
                if truth > 0.0:
                    errors.append((baked - truth) / truth)
                    if truth >= VISIBLE:
                        visible.append(errors[-1])
                else:
                    dark.append(baked)
        line = f"{name}: {summary(errors)}; of them at least {VISIBLE:g}: {summary(visible)}"
        if dark:
            line += f"; exactly dark: {len(dark)} values, tables up to {max(dark):.3g} W m^-2 sr^-1 nm^-1"
        print(line)


def summary(errors):
    rms = math.sqrt(sum(x * x for x in errors) / len(errors))
    magnitudes = sorted(abs(x) for x in errors)
    return (f"{len(errors)} values, relative error RMS {100 * rms:.3g}%, "
            f"median |.| {100 * statistics.median(magnitudes):.3g}%, "
            f"90th percentile {100 * magnitudes[int(0.9 * len(magnitudes))]:.3g}%, "
            f"max {100 * magnitudes[-1]:.3g}%")


if __name__ == "__main__":
    main()
