#!/usr/bin/python3
"""Colour error of a spectral set (tables in XYZ) against the committed
spectral reference.

Answers reference/cases/earth.csv with `skybake eval` from LUT_DIR and prints,
per case group (twilight split at sun zenith 90 and 96 degrees, as the
report splits it), the relative error of the luminance Y (RMS and largest)
and the chromaticity difference Delta u'v' (CIE 1976 UCS; RMS and largest)
against reference/cases/earth_spectral_reference.csv:

    /usr/bin/python3 scripts/colour_errors.py build/cli/skybake LUT_DIR

(`skybake report` gives the same comparison with the three-wavelength set read
as sRGB beside it; this is the quick check for one bake.)
"""
import csv
import math
import sys

from case_errors import CASES, evaluate


def ucs(x, y, z):
    d = x + 15.0 * y + 3.0 * z
    return (4.0 * x / d, 9.0 * y / d) if d > 0.0 else (0.0, 0.0)


def group_name(row):
    if row["group"] != "twilight":
        return row["group"]
    sun = float(row["sun_zenith_deg"])
    return "twilight to 90" if sun <= 90.0 else ("twilight 91-96" if sun <= 96.0 else "twilight 97-100")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    skybake, lut_dir = sys.argv[1], sys.argv[2]
    baked = evaluate(skybake, lut_dir, "earth.csv")
    with open(CASES / "earth_spectral_reference.csv") as f:
        reference = list(csv.DictReader(f))
    groups = {}
    for b, r in zip(baked, reference):
        quantity = "sky_irradiance" if r["group"] == "irradiance" else "radiance"
        if not r.get(f"{quantity}_Y") or not b.get(f"{quantity}_Y"):
            continue
        got = [float(b[f"{quantity}_{c}"]) for c in "XYZ"]
        expected = [float(r[f"{quantity}_{c}"]) for c in "XYZ"]
        if expected[1] <= 0.0:
            continue
        u, v = ucs(*got)
        u0, v0 = ucs(*expected)
        groups.setdefault(group_name(r), []).append((got[1] / expected[1] - 1.0, math.hypot(u - u0, v - v0)))
    rms = lambda values: math.sqrt(sum(x * x for x in values) / len(values))
    for name, values in groups.items():
        luminance = [e for e, _ in values]
        chromaticity = [d for _, d in values]
        print(f"{name:20s} {len(values):3d} cases  luminance RMS {100 * rms(luminance):6.3f} %  max "
              f"{100 * max(abs(e) for e in luminance):6.3f} %  du'v' RMS {rms(chromaticity):.4f}  max "
              f"{max(chromaticity):.4f}")


if __name__ == "__main__":
    main()
