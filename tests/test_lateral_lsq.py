"""The blocked, reduced least-squares problem of the lateral fits (tyredamp.lateral._lsq).

Every quantity is checked against an independent computation on the full
residual: the model's accelerance from ``LateralModel.response`` and the
Jacobian by central differences of that residual.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import tyredamp.lateral._lsq as lsq
from tyredamp.lateral import ClassicModel, HystereticModel, LateralModel, StretchedStringModel
from tyredamp.lateral._lsq import Lines, Problem, Segment

from .test_lateral_fit import TRUTHS

F = np.linspace(0.25, 9.0, 57)
#: the six models with their parameters (test_lateral_fit's truths)
MODELS: list[LateralModel] = TRUTHS


def _central(fun, x: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """Central differences of a vector function, one row per parameter."""
    rows = []
    for k in range(x.size):
        e = np.zeros_like(x)
        e[k] = h
        rows.append((fun(x + e) - fun(x - e)) / (2 * h))
    return np.array(rows)


def _cond(m: LateralModel) -> dict[str, float]:
    return m.conditions


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.name)
def test_mobility_gradient_is_the_derivative_in_log_parameters(model: LateralModel) -> None:
    w = 2 * np.pi * F
    got = model._mobility_gradient(w)
    if got is None:  # the string model: central differences in the fit
        assert isinstance(model, StretchedStringModel)
        return
    v, dv = got
    # The mobility returned with the gradient is the model's (rounding only).
    assert_allclose(v, model._mobility(w), rtol=1e-13)
    x = np.log(model.vector())

    def mob(lx: np.ndarray) -> np.ndarray:
        return type(model).from_vector(np.exp(lx), **_cond(model))._mobility(w)

    # Central differences with h = 1e-6 in ln p: truncation ~h^2, rounding ~eps/h.
    assert_allclose(dv, _central(mob, x), rtol=1e-7, atol=1e-9 * np.abs(v).max())


def _full(segs: list[Segment], x: np.ndarray) -> np.ndarray:
    """The stacked real residual computed from LateralModel.response (independent path)."""
    parts = []
    for s in segs:
        m = s.cls.from_vector(np.exp(s.log_params(x)), **s.cond)
        a = m.response(s.lines.frequency, "accelerance", s.force, s.wheel_mass)
        weights = np.abs(s.lines.w_iw) / s.lines.omega
        meas = s.lines.w_meas / weights
        r = weights * (a - meas)
        parts += [r.real, r.imag]
    return np.concatenate(parts)


def _segments(model: LateralModel, force: str, n: int = 1) -> list[Segment]:
    rng = np.random.default_rng(3)
    segs = []
    for i in range(n):
        a = model.response(F, "accelerance", force, 90.0)  # type: ignore[arg-type]
        a = a * (1 + 0.05 * rng.standard_normal(F.size)) * (1 + 0.1 * i)
        lines = Lines(F, a, 1.0 / np.abs(a))
        segs.append(Segment(type(model), _cond(model), lines, force, 90.0))  # type: ignore[arg-type]
    return segs


@pytest.mark.parametrize("force", ["ground", "axle"])
@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.name)
def test_blocked_products_equal_those_of_the_full_residual(
    model: LateralModel, force: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(lsq, "BLOCK", 10)  # several blocks and a short last one
    segs = _segments(model, force)
    x = np.log(model.vector()) + 0.1
    prob = Problem(segs, x.size)
    r = _full(segs, x)
    jac = _central(lambda lx: _full(segs, lx), x).T
    aug = np.column_stack([jac, r])
    gram, rss = prob.gram(x)
    assert_allclose(rss, r @ r, rtol=1e-12)
    assert_allclose(prob.rss(x), r @ r, rtol=1e-12)
    # Jacobian by central differences: relative accuracy ~1e-8 of the largest entries.
    scale = np.sqrt(np.outer(np.diag(aug.T @ aug), np.diag(aug.T @ aug)))
    assert np.max(np.abs(gram - aug.T @ aug) / scale) < 1e-6
    # The factors given to scipy and the QR factor reproduce the same products.
    f = prob.reduced(x)
    assert_allclose(f.T @ f, gram, rtol=0, atol=1e-12 * np.max(np.abs(gram)))
    r_aug, rss_qr = prob.qr(x)
    assert_allclose(rss_qr, r @ r, rtol=1e-12)
    assert np.max(np.abs(r_aug.T @ r_aug - aug.T @ aug) / scale) < 1e-6
    # Singular values of J (the standard errors) from R, against the full Jacobian.
    p = x.size
    assert_allclose(
        np.linalg.svd(r_aug[:p, :p], compute_uv=False),
        np.linalg.svd(jac, compute_uv=False),
        rtol=1e-6,
    )


def test_joint_map_gives_the_chain_rule() -> None:
    """Shared parameters through ``log p_i = T_i x + b_i``: ``J_x = J_p T`` per segment."""
    model = HystereticModel(K=1.3e5, h=1.8e4, C_r=5e4)
    segs = _segments(model, "ground", n=2)
    t = np.eye(3)
    joint = [
        Segment(s.cls, s.cond, s.lines, s.force, s.wheel_mass, t, np.array([0, 0, -math.log(v)]))
        for s, v in zip(segs, (2.0, 4.0), strict=True)
    ]
    x = np.log(model.vector()) + np.array([0.0, 0.0, math.log(3.0)])
    prob = Problem(joint, 3)
    r = _full(joint, x)
    jac = _central(lambda lx: _full(joint, lx), x).T
    gram, rss = prob.gram(x)
    assert_allclose(rss, r @ r, rtol=1e-12)
    aug = np.column_stack([jac, r])
    scale = np.sqrt(np.outer(np.diag(aug.T @ aug), np.diag(aug.T @ aug)))
    assert np.max(np.abs(gram - aug.T @ aug) / scale) < 1e-6


def test_rejected_parameters_cost_as_before() -> None:
    """A parameter vector the model refuses costs ``1e100`` per residual (the former _safe)."""
    model = ClassicModel(k=1.3e5, c=2e3)
    segs = _segments(model, "ground")
    prob = Problem(segs, 2)
    bad = np.array([800.0, 0.0])  # exp overflows: the model cannot be built
    n = 2 * F.size
    assert prob.rss(bad) == pytest.approx(1e200 * n)
    f = prob.reduced(bad)
    assert_allclose(f[:, -1] @ f[:, -1], 1e200 * n, rtol=1e-12)
    assert np.all(f[:, :-1] == 0)
