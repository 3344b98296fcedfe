"""Benchmark: what each scene reduction saves and what it changes, against the full model.

    python -m harness.benchmarks.scene_reductions [--quick]

Model A, the scaled stick-slip set (k_d = V_d = 1e-2, gamma_t = 5e-3), plate at
omega = 0.8, started on the steady orbit.  Two contacts: the paper's soft one
(k_n/m = 1, gamma_n = 0.07) and a hard one (k_n/m = 1e4, same damping ratio 0.035).

For every variant (the full model, each reduction, and the full model with the stiff-
stable integrator):

* step: the largest dt of the ladder 4e-4, 2e-3, 1e-2, 5e-2, 0.2, 1 that the variant
  admits and at which phi(A = 0.3) stays within 2 % of its own value at dt = 4e-4;
* phi at A = 0.3 (stick-slip for the full model), its change against the full model at
  the paper's dt, and the wall time of that run;
* phi at A = 2 (sliding, above every threshold) at the variant's step, and its change;
* speed-up: the full model's time at dt = 4e-4 over the variant's at its step, and
  (fair) over the full model's at its own step;
* boundary: the amplitude where phi falls below PHI_C (stick-slip -> sliding), by
  bisection on [0.2, 2.6] to 0.005, and its change against the full model.

phi = <(vx - V_d)^2> / V_d^2 over the window [TRANSIENT, TRANSIENT + WINDOW] (several
stick-slip cycles: the stick time is ~5e3).  Times are wall times on this machine, one
core, compiled kernels warm; a shared machine makes them noisy at the 20 % level.
"""
from __future__ import annotations

import argparse
import time

from vibroblock import Block, ModelError, detachment_amplitude

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
OMEGA = 0.8
A_WORK = 0.3  # the working point: below both thresholds (A_c(0.8) = 0.57, g / omega^2 = 1.56)
A_SLIDING = 2.0  # above every threshold: the block bounces and slides
PHI_C = 10.0  # stick-slip above, sliding below (the full model's phi: ~125 stick-slip, ~1 sliding)
DT_LADDER = (4e-4, 2e-3, 1e-2, 5e-2, 0.2, 1.0)
TOLERANCE = 0.02
CONTACTS = {
    "soft contact (paper): k_n/m = 1": {"k_n": 1.0, "gamma_n": 0.07},
    "hard contact: k_n/m = 1e4": {"k_n": 1e4, "gamma_n": 7.0},
}
VARIANTS = {
    "full model": ("symplectic_euler", {}),
    "frozen_vertical": ("symplectic_euler", {"frozen_vertical": True}),
    "rigid_contact": ("symplectic_euler", {"rigid_contact": True}),
    "coulomb_friction": ("symplectic_euler", {"coulomb_friction": True}),
    "rigid + coulomb": ("symplectic_euler", {"rigid_contact": True, "coulomb_friction": True}),
    "frozen + coulomb": ("symplectic_euler", {"frozen_vertical": True, "coulomb_friction": True}),
    "full, implicit_contact": ("implicit_contact", {}),
}


def measure_phi(integrator, scene, contact, amplitude, dt, transient, window):
    """phi over the window and the wall time of the run (None if the variant refuses dt)."""
    block = Block("A", integrator, initial_state=2, dt=dt, A=amplitude, omega=OMEGA, **SCALED, **contact, **scene)
    try:
        block.start()
    except ModelError:
        return None, None
    block.advance_to(dt)  # kernels loaded outside the timing
    started = time.perf_counter()
    block.advance_to(transient)
    before = block.output("phi_integral")
    block.advance_to(transient + window)
    elapsed = time.perf_counter() - started
    return (block.output("phi_integral") - before) / window / SCALED["V_d"] ** 2, elapsed


def working_step(integrator, scene, contact, transient, window):
    """The largest ladder dt keeping phi(A_WORK) within TOLERANCE of its dt = 4e-4 value."""
    reference, reference_time = measure_phi(integrator, scene, contact, A_WORK, DT_LADDER[0], transient, window)
    best = (DT_LADDER[0], reference, reference_time)
    for dt in DT_LADDER[1:]:
        phi, elapsed = measure_phi(integrator, scene, contact, A_WORK, dt, transient, window)
        if phi is None or abs(phi - reference) > TOLERANCE * abs(reference):
            break
        best = (dt, phi, elapsed)
    return reference, reference_time, best


def boundary(integrator, scene, contact, dt, transient, window, iterations):
    """Amplitude at which phi falls below PHI_C (None: no stick-slip phase at all)."""
    lo, hi = 0.2, 2.6
    phi_lo, _ = measure_phi(integrator, scene, contact, lo, dt, transient, window)
    if phi_lo < PHI_C:
        return None
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        phi, _ = measure_phi(integrator, scene, contact, mid, dt, transient, window)
        lo, hi = (mid, hi) if phi >= PHI_C else (lo, mid)
    return 0.5 * (lo + hi)


def run_benchmark(quick: bool = False) -> list[dict]:
    transient, window, iterations = (500.0, 6000.0, 4) if quick else (2000.0, 20000.0, 9)
    rows = []
    for contact_name, contact in CONTACTS.items():
        full = None
        for name, (integrator, scene) in VARIANTS.items():
            phi_paper_dt, time_paper_dt, (dt, phi, elapsed) = working_step(integrator, scene, contact, transient,
                                                                            window)
            row = {"contact": contact_name, "variant": name, "dt": dt, "phi": phi, "time": elapsed,
                   "phi_paper_dt": phi_paper_dt, "time_paper_dt": time_paper_dt,
                   "phi_sliding": measure_phi(integrator, scene, contact, A_SLIDING, dt, transient, window)[0],
                   "boundary": boundary(integrator, scene, contact, dt, transient, window, iterations)}
            if full is None:
                full = row
            row["speedup_vs_paper_dt"] = full["time_paper_dt"] / elapsed
            row["speedup_vs_full_best_dt"] = full["time"] / elapsed
            row["dphi"] = phi - full["phi_paper_dt"]
            row["dphi_sliding"] = row["phi_sliding"] - full["phi_sliding"]
            row["dboundary"] = (None if row["boundary"] is None or full["boundary"] is None
                                else row["boundary"] - full["boundary"])
            rows.append(row)
    return rows


def format_table(rows: list[dict], quick: bool = False) -> str:
    transient, window = (500.0, 6000.0) if quick else (2000.0, 20000.0)
    lines = [f"Scene reductions, model A, scaled set {SCALED}, omega = {OMEGA}; phi at A = {A_WORK} over "
             f"[{transient:g}, {transient + window:g}]; boundary: phi < {PHI_C:g} (bisection on A).",
             f"Detachment thresholds at omega = {OMEGA}: compliant A_c = {float(detachment_amplitude(OMEGA)):.3f}, "
             f"rigid g/omega^2 = {1 / OMEGA**2:.3f}.",
             "step: largest dt of the ladder keeping phi within 2 % of the variant's own value at dt = 4e-4.",
             "",
             f"{'contact':34} {'variant':24} {'step':>7} {'ns/step':>7} {'phi':>8} {'dphi':>8} {'phi A=2':>8} "
             f"{'dphi':>7} {'time s':>7} {'x paper dt':>10} {'x full best':>11} {'boundary A':>10} {'dA':>7}"]
    for r in rows:
        bound = "none" if r["boundary"] is None else f"{r['boundary']:.3f}"
        dbound = "-" if r["dboundary"] is None else f"{r['dboundary']:+.3f}"
        per_step = r["time"] / ((transient + window) / r["dt"]) * 1e9
        lines.append(f"{r['contact']:34} {r['variant']:24} {r['dt']:7.0e} {per_step:7.0f} {r['phi']:8.3g} {r['dphi']:+8.3g} "
                     f"{r['phi_sliding']:8.3g} {r['dphi_sliding']:+7.2g} {r['time']:7.3f} {r['speedup_vs_paper_dt']:10.3g} {r['speedup_vs_full_best_dt']:11.3g} "
                     f"{bound:>10} {dbound:>7}")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="short window and coarse bisection (a smoke run)")
    args = parser.parse_args(argv)
    print(format_table(run_benchmark(args.quick), args.quick))


if __name__ == "__main__":
    from harness.benchmarks import recorded

    with recorded("scene_reductions"):
        main()
