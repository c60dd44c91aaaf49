#!/usr/bin/python3
"""Relative error of a baked set against the committed Monte Carlo reference.

Answers reference/cases/earth.csv, earth_aerial_horizon.csv,
earth_twilight.csv and earth_twilight_between.csv with `skybake eval` from LUT_DIR and prints, per case
group and quantity, the RMS and largest relative error over the cases and
the three wavelengths, and the reference's largest relative standard error
there (an error below about twice it is noise):

    /usr/bin/python3 scripts/case_errors.py build/cli/skybake LUT_DIR

(`skybake report` gives the same comparison per wavelength and in luminance,
with the reference's noise; this is the quick check for one bake.)
"""
import csv
import io
import math
import pathlib
import subprocess
import sys

CASES = pathlib.Path(__file__).resolve().parent.parent / "reference" / "cases"
CHANNELS = ["680nm", "550nm", "440nm"]


def evaluate(skybake, lut_dir, cases):
    out = subprocess.run([skybake, "eval", lut_dir, "--in", str(CASES / cases)], capture_output=True, text=True,
                         check=True).stdout
    return list(csv.DictReader(io.StringIO(out)))


def report(baked, reference, quantities):
    groups = {}
    for b, r in zip(baked, reference):
        for quantity in quantities:
            for c in CHANNELS:
                key = f"{quantity}_{c}"
                if not r.get(key) or not b.get(key) or float(r[key]) <= 0.0:
                    continue
                stderr = r.get(f"{quantity}_stderr_{c}") or "0"
                groups.setdefault(f"{r['group']}: {quantity}", []).append(
                    (float(b[key]) / float(r[key]) - 1.0, float(stderr) / float(r[key])))
    for name, values in sorted(groups.items()):
        errors = [e for e, _ in values]
        rms = math.sqrt(sum(e * e for e in errors) / len(errors))
        noise = max(s for _, s in values)
        print(f"{name:52s} RMS {100 * rms:8.3f}%  max {100 * max(abs(e) for e in errors):8.3f}%  "
              f"({len(errors)} values; reference standard error up to {100 * noise:.3g}%)")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    skybake, lut_dir = sys.argv[1], sys.argv[2]
    for cases, quantities in [("earth", ["radiance", "sky_irradiance"]),
                              ("earth_aerial_horizon", ["radiance", "transmittance"]),
                              ("earth_twilight", ["radiance", "sky_irradiance"]),
                              ("earth_twilight_between", ["radiance"])]:
        with open(CASES / f"{cases}_reference.csv") as f:
            reference = list(csv.DictReader(f))
        report(evaluate(skybake, lut_dir, f"{cases}.csv"), reference, quantities)


if __name__ == "__main__":
    main()
