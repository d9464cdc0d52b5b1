#!/usr/bin/env python3
"""Prints the numbers docs/reproduction.md quotes, read from the JSON that scripts/reproduce.sh
keeps in its output directory (the only argument). A run that was skipped (--fast) is named
and left out. Standard library only."""
import json
import math
import os
import sys

out = sys.argv[1]


def load(name):
    path = os.path.join(out, name)
    if not os.path.exists(path):
        print(f"\n({name}: not run)")
        return None
    with open(path) as f:
        return json.load(f)


def idx(doc, t):
    ts = doc["t_s"]
    return min(range(len(ts)), key=lambda k: abs(ts[k] - t))


def scenarios(doc):
    """The per-trajectory documents (a single --trajectory run is one flat document)."""
    return doc["scenarios"] if "scenarios" in doc else [doc]


def curve(s, name):
    """A filter's RMSE curve (m): from `filters` when several ran, else the EKF's."""
    f = s.get("filters")
    if f and name in f:
        return f[name]["rmse_m"]
    return s["rmse_ekf_m"] if name == "ekf" else None


def failed(s):
    f = s.get("filters")
    if f:
        return ", ".join(f"{k} {v['failed_runs']} of {v['runs'] + v['failed_runs']}" for k, v in f.items())
    return f"ekf {s['failed_runs']} of {s['failed_runs'] + s['runs']}"


def fig3(name, label):
    d = load(name)
    if d is None:
        return
    print(f"\n{label}: eps_PCRLB (cm) and eps_EKF / eps_PCRLB at 1, 2, 5, 10 s")
    print("scenario | eps_PCRLB 1 / 2 / 5 / 10 s        | ratio 1 s   2 s   5 s  10 s | failed runs")
    for s in scenarios(d):
        ii = [idx(s, t) for t in (1, 2, 5, 10)]
        p = [s["rmse_pcrlb_m"][i] * 100 for i in ii]
        r = [s["rmse_ekf_m"][i] / s["rmse_pcrlb_m"][i] for i in ii]
        print(f"{s['trajectory']:>8} | " + " / ".join(f"{x:.3f}" for x in p)
              + " | " + " ".join(f"{x:5.3f}" for x in r) + f" | {failed(s)}")
        if name == "fig3.json" or name == "fig3_filters.json":
            lo, hi = min(s["nees"][i] for i in ii), max(s["nees"][i] for i in ii)
            print(f"{'':>8}   average NEES at these times {lo:.2f}-{hi:.2f}")


def filters_paper(name, label, names, times):
    d = load(name)
    if d is None:
        return
    print(f"\n{label}: RMSE (mm) at {', '.join(f'{t} s' for t in times)}")
    for s in scenarios(d):
        for t in times:
            i = idx(s, t)
            p = s["rmse_pcrlb_m"][i] * 1e3
            vals = [(n, curve(s, n)[i] * 1e3) for n in names]
            cells = ", ".join(f"{n} {v:.3f} ({v / p:.3f}x)" for n, v in vals)
            if "pf" in names:
                cells += f", pf/ekf {curve(s, 'pf')[i] / curve(s, 'ekf')[i]:.2f}"
            print(f"{s['trajectory']:>4} {t:>4} s: PCRLB {p:.3f}, {cells}")
        print(f"{'':>4} failed runs: {failed(s)}")
        if "ukf" in names:
            diff = max(abs(curve(s, "ukf")[idx(s, t)] - curve(s, "ekf")[idx(s, t)]) for t in (1, 2, 5, 10))
            print(f"{'':>4} max |UKF - EKF| at 1, 2, 5, 10 s: {diff * 1e6:.3f} um")


def filters_fast():
    for s_name in ("II", "III"):
        a, b = load(f"filters_fast_{s_name}.json"), load(f"pf10k_fast_{s_name}.json")
        if a is None or b is None:
            continue
        print(f"\nfast profile, scenario {s_name}, 200 x 5 runs: RMSE (mm)")
        print("   t | PCRLB | EKF | UKF | PF 1000 | PF 10 000")
        for t in (2, 5, 10):
            i = idx(a, t)
            v = [a["rmse_pcrlb_m"][i], curve(a, "ekf")[i], curve(a, "ukf")[i], curve(a, "pf")[i],
                 curve(b, "pf")[i]]
            print(f"{t:>4} s | " + " | ".join(f"{x * 1e3:.2f}" for x in v))
        print(f"     failed runs: {failed(a)}; PF 10 000: {failed(b)}")


def roc(name, label, at):
    d = load(name)
    if d is None:
        return
    extra = f", {d['disagreements']} size-rule/i.c.b disagreements (check 6)" if name == "va.json" else ""
    print(f"\n{label} ({d['realisations']} realisations{extra})")
    for c in d["curves"]:
        pts = c["points"]
        best = max(pts, key=lambda p: p["p_d"])
        sel = [p for p in pts if any(abs(p["threshold"] - t) < 1e-9 for t in at)] if at else []
        row = "; ".join(f"T {p['threshold']:g}: P_D {p['p_d']:.3f} P_FA {p['p_fa']:.3f}" for p in sel)
        print(f"  {c['label']}: peak P_D {best['p_d']:.3f} at T {best['threshold']:g}; "
              f"first P_D {pts[0]['p_d']:.3f}, last P_D {pts[-1]['p_d']:.3f} P_FA {pts[-1]['p_fa']:.3f}"
              + (f"\n    {row}" if row else ""))


def walk():
    tr, truth = load("track.json"), load(os.path.join("walk", "truth.json"))
    if tr is None or truth is None:
        return
    tt = {round(t, 6): x for t, x in zip(truth["t_s"], truth["states"])}
    err = [math.hypot(x[0] - tt[round(t, 6)][0], x[1] - tt[round(t, 6)][1])
           for t, x in zip(tr["t_s"], tr["states"]) if t > 1.0 + 1e-9 and round(t, 6) in tt]
    links = len(tr["links_used"]) * len(tr["start"]["delays_used_s"])
    absent = links - sum(tr["links_used"])
    print("\nspec 9.6 stand-in (q = 0.1, start at rest, sigma_v = 2 m/s):")
    print(f"  position error after the first second: {math.sqrt(sum(e * e for e in err) / len(err)) * 100:.1f} cm RMS, "
          f"at most {max(err) * 100:.1f} cm; link-steps absent: {absent} of {links}")


fig3("fig3.json", "[S] Fig. 3, paper scale")
fig3("fig3_fast.json", "[S] Fig. 3, fast profile")
filters_paper("fig3_filters.json", "EKF and UKF, paper scale", ["ekf", "ukf"], (2, 5, 10))
filters_paper("fig3_pf.json", "EKF and PF, 160 runs at the paper step", ["ekf", "pf"], (1, 2, 5, 10))
filters_fast()
t2 = os.path.join(out, "table2.txt")
if os.path.exists(t2):
    print("\n[A] Table II (mtl table2):")
    print(open(t2).read().rstrip())
roc("va.json", "[A] Fig. 3 (V-A), over T_e", [])
roc("vb.json", "[A] Fig. 4 (V-B), over T_b", [2, 4, 6, 11, 20])
roc("vc.json", "[A] Fig. 5 (V-C), over T_b (1 - P_D is the missed detection)", [2, 11, 20])
walk()
for name, label in (("plan_summary.json", "4 receivers"), ("plan_all_summary.json", "all 5 nodes")):
    p = load(name)
    if p is not None:
        print(f"\nplan, sensors2019, p90 over the area, {label}: {p['before'] * 100:.2f} -> {p['after'] * 100:.2f} cm "
              f"({p['evaluations']} evaluations, {p['wall_time_s']:.2f} s)")
