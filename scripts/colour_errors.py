#!/usr/bin/python3
"""Colour error of a spectral bake, and of three wavelengths read as sRGB.

Answers reference/cases/earth.csv with `skybake eval` from a spectral set
(`skybake bake earth --wavelengths 15`, tables in CIE XYZ) and from a
three-wavelength set (`skybake bake earth`), and prints per case group,
against reference/cases/earth_spectral_reference.csv (`skybake reference
--wavelengths 15`, converted exactly): the relative error of the luminance Y
(RMS and largest) and the chromaticity difference Delta u'v' (CIE 1976 UCS;
RMS and largest). The three-wavelength set's 680/550/440 nm values are read
as linear sRGB, as engines read them; its luminance is compared after the one
scale, fitted on the daylight group, that turns its units into cd m^-2.

    /usr/bin/python3 scripts/colour_errors.py build/cli/skybake SPECTRAL_DIR THREE_WAVELENGTH_DIR [--markdown]
"""
import csv
import io
import math
import pathlib
import subprocess
import sys

CASES = pathlib.Path(__file__).resolve().parent.parent / "reference" / "cases"
# Linear sRGB (Rec. 709 primaries, D65) to XYZ, IEC 61966-2-1.
SRGB_TO_XYZ = [[0.4124564, 0.3575761, 0.1804375],
               [0.2126729, 0.7151522, 0.0721750],
               [0.0193339, 0.1191920, 0.9503041]]
GROUPS = ["daylight", "horizon", "space", "aerial_perspective", "twilight to sun 90", "twilight 91-96",
          "twilight 97-100", "sky irradiance"]


def evaluate(skybake, lut_dir):
    out = subprocess.run([skybake, "eval", lut_dir, "--in", str(CASES / "earth.csv")], capture_output=True,
                         text=True, check=True).stdout
    return list(csv.DictReader(io.StringIO(out)))


def uv(xyz):
    x, y, z = xyz
    d = x + 15.0 * y + 3.0 * z
    return (4.0 * x / d, 9.0 * y / d)


def values(table, quantity, columns):
    return [None if not r.get(f"{quantity}_{columns[0]}") else [float(r[f"{quantity}_{c}"]) for c in columns]
            for r in table]


def group_of(row, quantity):
    if quantity == "sky_irradiance":
        return "sky irradiance"
    if row["group"] != "twilight":
        return row["group"]
    sun = float(row["sun_zenith_deg"])
    return "twilight to sun 90" if sun <= 90 else "twilight 91-96" if sun <= 96 else "twilight 97-100"


def errors(baked, reference_rows, scale=1.0):
    """{group: [(relative luminance error, delta u'v')]} over radiance and sky irradiance."""
    groups = {}
    for quantity in ("radiance", "sky_irradiance"):
        ref = values(reference_rows, quantity, ["X", "Y", "Z"])
        for b, r, row in zip(baked[quantity], ref, reference_rows):
            if b is None or r is None or r[1] <= 0.0:
                continue
            (bu, bv), (ru, rv) = uv(b), uv(r)
            groups.setdefault(group_of(row, quantity), []).append((scale * b[1] / r[1] - 1.0,
                                                                   math.hypot(bu - ru, bv - rv)))
    return groups


def stats(pairs):
    lum = [e for e, _ in pairs]
    duv = [d for _, d in pairs]
    rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v))
    return rms(lum), max(abs(e) for e in lum), rms(duv), max(duv)


def main():
    args = [a for a in sys.argv[1:] if a != "--markdown"]
    if len(args) != 3:
        sys.exit(__doc__)
    skybake, spectral_dir, three_dir = args
    with open(CASES / "earth_spectral_reference.csv") as f:
        reference = list(csv.DictReader(f))
    spectral_table = evaluate(skybake, spectral_dir)
    spectral = {q: values(spectral_table, q, ["X", "Y", "Z"]) for q in ("radiance", "sky_irradiance")}
    three_table = evaluate(skybake, three_dir)
    as_srgb = {}
    for q in ("radiance", "sky_irradiance"):
        rgb = values(three_table, q, ["680nm", "550nm", "440nm"])
        as_srgb[q] = [None if v is None else [sum(m[k] * v[k] for k in range(3)) for m in SRGB_TO_XYZ] for v in rgb]
    ref_radiance = values(reference, "radiance", ["X", "Y", "Z"])
    day = [(b[1], r[1]) for b, r, row in zip(as_srgb["radiance"], ref_radiance, reference) if row["group"] == "daylight"]
    scale = sum(r * b for b, r in day) / sum(b * b for b, r in day)
    a, b = errors(spectral, reference), errors(as_srgb, reference, scale)
    if "--markdown" in sys.argv:
        print("| case group | cases | spectral: luminance RMS / max | spectral: Δu′v′ RMS / max "
              "| 680/550/440 nm as sRGB: luminance RMS / max | as sRGB: Δu′v′ RMS / max |")
        print("| --- | ---: | ---: | ---: | ---: | ---: |")
        for g in GROUPS:
            if g not in a:
                continue
            sa, sb = stats(a[g]), stats(b[g])
            print(f"| {g} | {len(a[g])} | {100 * sa[0]:.2f} % / {100 * sa[1]:.2f} % | {sa[2]:.4f} / {sa[3]:.4f} "
                  f"| {100 * sb[0]:.2f} % / {100 * sb[1]:.2f} % | {sb[2]:.4f} / {sb[3]:.4f} |")
        print(f"\nThe three-wavelength set's luminance is scaled by {scale:.4g} (fitted on daylight).")
        return
    for name, groups in (("spectral", a), ("RGB as sRGB", b)):
        for g in GROUPS:
            if g in groups:
                s = stats(groups[g])
                print(f"{name:12s} {g:22s} luminance RMS {100 * s[0]:7.3f}% max {100 * s[1]:7.3f}%   "
                      f"du'v' RMS {s[2]:.5f} max {s[3]:.5f}   ({len(groups[g])} cases)")


if __name__ == "__main__":
    main()
