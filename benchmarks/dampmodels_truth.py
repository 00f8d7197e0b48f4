"""Non-viscous truths: A-W part 2's chain and the rubber tyre against viscous estimates.

1. The example system of Adhikari & Woodhouse, "Identification of damping:
   part 2, non-viscous damping", J. Sound Vib. 243(1) (2001) 63-88, sec. 4: a
   chain of 30 unit masses between springs ``k_u``, dashpots between masses 8
   and 17, an exponential kernel with ``gamma = theta / T_min`` (``T_min`` the
   period of the highest mode) of 0.02 (nearly viscous) and 0.5 (strongly
   non-viscous). From the exact complex modes: the relaxation time found by
   :func:`tyredamp.dampmodels.exponential_from_modes`, the asymmetry of the
   part-1 viscous fit before and after, the viscous-consistency verdict.
   (``k_u = 4e5 N/m``, ``c = 40 N s/m``: the spring and dashpot values are this
   benchmark's; the paper's figures give the setup and ``gamma``.)
2. The virtual ring tyre with the default tread rubber (a Prony series fitted
   to the fractional Zener law on 10-300 Hz) on sidewalls and band: the exact
   modes (augmented state space) against the part-1 viscous identification of
   the same exact modes at the 16 measurement points (damping ratios), and the
   A-W test on them.

Run: ``python benchmarks/dampmodels_truth.py``.
"""

from __future__ import annotations

import time

import numpy as np

from tyredamp.damping import modal_damping_from_modes
from tyredamp.dampmodels import DampedSystem, Exponential, Viscous, exponential_from_modes
from tyredamp.virtual import RingTyre
from tyredamp.virtual.rubber import DEFAULT_TREAD, fit_prony, rubber_system


def chain() -> None:
    n, k_u, c_u = 30, 4e5, 40.0
    K = 2 * k_u * np.eye(n) - k_u * (np.eye(n, k=1) + np.eye(n, k=-1))
    C = np.zeros((n, n))
    for i in range(7, 16):
        C[i : i + 2, i : i + 2] += c_u * np.array([[1.0, -1.0], [-1.0, 1.0]])
    t_min = 2 * np.pi / np.sqrt(np.linalg.eigvalsh(K).max())
    print("A-W part 2 chain, 30 masses, all modes, exact complex modes")
    print("  gamma   theta true [s]  theta found [s]  error   asym before  after  verdict")
    for gamma in (0.0, 0.02, 0.1, 0.5, 1.0):
        theta = gamma * t_min
        law = Viscous(C) if gamma == 0 else Exponential(C, np.array([1 / theta]))
        md = DampedSystem(np.eye(n), K, law).modes()
        est = exponential_from_modes(md.poles, md.shapes * np.sqrt(2j * md.poles.imag))
        err = f"{100 * (est.theta / theta - 1):6.2f} %" if theta else "   -   "
        verdict = "viscous" if est.viscous_consistent else "non-viscous"
        print(
            f"  {gamma:5.2f}  {theta:14.4g}  {est.theta:15.4g}  {err}  "
            f"{100 * est.asymmetry:9.3g} %  {100 * est.asymmetry_after:5.2g} %  {verdict}"
        )


def tyre() -> None:
    t0 = time.perf_counter()
    ring = RingTyre()
    prony = fit_prony(DEFAULT_TREAD, 10.0, 300.0, per_decade=1)
    sys_ = rubber_system(ring, prony)
    md = sys_.modes(max_hz=200.0)
    keep = md.frequency_hz < 160.0
    p, x = md.poles[keep], md.shapes[:, keep]
    pts = ring.point_dofs
    shapes = x[pts] * np.sqrt(2j * p.imag)
    est = modal_damping_from_modes(p, shapes, method="first")
    zeta_visc = np.diag(est.c_modal) / (2 * est.omega)
    dt = time.perf_counter() - t0
    print(f"\nring tyre with tread rubber (Prony, {prony.e_k.size} terms), {dt:.1f} s")
    print("  f [Hz]   zeta exact   zeta viscous (part 1)   ratio")
    for f, z, zv in zip(md.frequency_hz[keep], md.damping_ratio[keep], zeta_visc, strict=True):
        print(f"  {f:6.1f}   {z:10.4f}   {zv:21.4f}   {zv / z:6.3f}")
    aw = exponential_from_modes(p, shapes)
    print("  " + aw.format())


if __name__ == "__main__":
    chain()
    tyre()
