#!/usr/bin/env python3
"""The CRLB map in vectorised numpy: the reference the Rust map kernel is compared against in
docs/benchmarks.md (issue 13 §1).

Computes the same map as `scatterloc crlb-map` (spec delay-localization.md §7, E8, S24) from a
scenario JSON, independently: link budget, exact §9.3 Tx pattern (arccos + exp, no polynomial),
unit vectors, Fisher sums and the RMSE bound, all as whole-array numpy operations over the grid.
It checks its map against the CLI's JSON when one is given, then times the map alone (link
budget excluded) as the median of --repeat runs.

Usage (needs numpy; not part of the test suite):
    scatterloc preset sensors2019 > s.json
    scatterloc crlb-map --scenario s.json --nx 256 --ny 256 --out map.json
    python3 scripts/numpy_map.py s.json --n 256 --check map.json
"""

import argparse
import json
import math
import statistics
import time

import numpy as np

C = 299_792_458.0
K_B = 1.380_649e-23
T0 = 290.0
SINGULAR_RCOND = 1e-12


def db(x):
    return 10.0 ** (x / 10.0)


def link_weights(s):
    """Per link: 8π²β²/c² · P_Tx G_Rx σ c² G_p / ((4π)³ f_c² P_n) (E8 at unit distances/gain)."""
    radio = s["radio"]
    if radio.get("noise_power_dbm") is not None:
        pn = db(radio["noise_power_dbm"]) * 1e-3
    else:
        pn = K_B * T0 * radio["bandwidth_hz"] * db(radio.get("noise_figure_db", 10.0) or 10.0)
    pg = db(radio.get("processing_gain_db") or 0.0)
    fc = radio["carrier_hz"]
    beta2 = radio["bandwidth_hz"] ** 2 / 12.0
    txs = {t["name"]: i for i, t in enumerate(s["transmitters"])}
    rxs = {r["name"]: i for i, r in enumerate(s["receivers"])}
    if s.get("links", "all") == "all":
        pairs = [(k, l) for l in range(len(rxs)) for k in range(len(txs))]
    else:
        pairs = [(txs[a], rxs[b]) for a, b in s["links"]]
    k = 8.0 * math.pi**2 * beta2 / C**2
    out = []
    for tx, rx in pairs:
        t, r = s["transmitters"][tx], s["receivers"][rx]
        snr = (db(t["power_dbm"]) * 1e-3 * db(r["gain_dbi"]) * s["target"]["rcs_m2"] * C * C * pg
               / ((4 * math.pi) ** 3 * fc * fc * pn))
        out.append((tx, rx, k * snr))
    return out


def crlb_map(s, links, n):
    area = s["area_m"]
    xs = area["x"][0] + (np.arange(n) + 0.5) * (area["x"][1] - area["x"][0]) / n
    ys = area["y"][0] + (np.arange(n) + 0.5) * (area["y"][1] - area["y"][0]) / n
    X, Y = np.meshgrid(xs, ys)  # row j = y_j

    def view(p):
        dx, dy = X - p[0], Y - p[1]
        d2 = dx * dx + dy * dy
        d = np.sqrt(d2)
        with np.errstate(divide="ignore"):
            inv = np.where(d < 1e-9, 0.0, 1.0 / d)
        return dx * inv, dy * inv, 1.0 / np.maximum(d2, 1.0)

    tx_views = []
    for t in s["transmitters"]:
        ux, uy, w = view(t["position_m"])
        g0 = db(t["gain_dbi"])
        pat = t.get("pattern", {"kind": "omni"})
        if pat.get("kind", "omni") == "omni":
            gain = g0
        else:
            phi = math.radians(pat["boresight_deg"])
            psi3 = math.radians(pat["beamwidth_deg"])
            cos_psi = np.clip(ux * math.cos(phi) + uy * math.sin(phi), -1.0, 1.0)
            psi = np.arccos(cos_psi)
            floor_angle = psi3 * math.sqrt(pat["floor_db"] / 12.0)
            main = g0 * np.exp(-1.2 * math.log(10.0) / psi3**2 * psi * psi)
            gain = np.where(psi >= floor_angle, g0 * db(-pat["floor_db"]), main)
            gain = np.where((ux == 0) & (uy == 0), g0, gain)
        tx_views.append((ux, uy, w * gain))
    rx_views = [view(r["position_m"]) for r in s["receivers"]]
    a = np.zeros_like(X)
    b = np.zeros_like(X)
    c = np.zeros_like(X)
    for tx, rx, w in links:
        tux, tuy, tw = tx_views[tx]
        rux, ruy, rw = rx_views[rx]
        gx, gy = tux + rux, tuy + ruy
        wp = w * tw * rw
        a += wp * gx * gx
        b += wp * gx * gy
        c += wp * gy * gy
    det = a * c - b * b
    tr = a + c
    regular = (tr > 0) & (det > SINGULAR_RCOND * tr * tr) & np.isfinite(det)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(regular, np.sqrt(tr / det), np.inf)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario")
    ap.add_argument("--n", type=int, default=256, help="grid side (n × n cells)")
    ap.add_argument("--repeat", type=int, default=30)
    ap.add_argument("--check", help="a `scatterloc crlb-map --out map.json` of the same grid")
    args = ap.parse_args()
    s = json.load(open(args.scenario))
    links = link_weights(s)
    m = crlb_map(s, links, args.n)
    if args.check:
        ref = json.load(open(args.check))
        want = np.array([[np.inf if v is None else v for v in row] for row in ref["rmse_bound_m"]])
        if want.shape != m.shape:
            want = want.reshape(m.shape)
        both = np.isfinite(want) & np.isfinite(m)
        assert (np.isfinite(want) == np.isfinite(m)).all(), "bounded cells differ"
        rel = np.max(np.abs(m[both] - want[both]) / want[both])
        # The kernel's Tx gain is a Chebyshev fit within 1e-12 of the exact pattern used here.
        assert rel < 1e-9, f"max relative difference {rel:e}"
        print(f"check: equal to the CLI map within {rel:.1e} relative on {both.sum()} cells")
    times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        crlb_map(s, links, args.n)
        times.append((time.perf_counter() - t0) * 1e3)
    print(json.dumps({
        "grid": f"{args.n}x{args.n}", "links": len(links), "numpy": np.__version__,
        "median_ms": round(statistics.median(times), 3), "min_ms": round(min(times), 3),
    }))


if __name__ == "__main__":
    main()
