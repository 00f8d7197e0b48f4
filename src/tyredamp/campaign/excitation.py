"""What a campaign's excitation layout can drive: the doubled modes a shaker layout sees.

Used by the test status (:func:`tyredamp.campaign.status.excitation_layout`)
to list, for a ring test, the wave numbers of which the shakers drive only one
member of the doubled pair.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["single_member_wave_numbers"]


def single_member_wave_numbers(
    input_angles_deg: Sequence[float], n_max: int, ratio: float = 0.1
) -> list[int]:
    """Wave numbers of which the excitation drives only one member of the doubled pair.

    The doubled modes of wave number ``n`` of a ring have the shapes
    ``cos n(theta - theta_0)`` and ``sin n(theta - theta_0)``; shakers at the
    angles ``theta_k`` drive them through the rows ``[cos n theta_k, sin n theta_k]``.
    When this ``K x 2`` matrix has rank one, every shaker sits on a nodal line of
    the same member, whatever ``theta_0``, and that member never appears in
    the FRFs (for two shakers 90 deg apart: every even ``n``; for one shaker:
    every ``n``). A wave number is listed when the smaller singular value of
    the matrix is below ``ratio`` times the larger.

    Parameters
    ----------
    input_angles_deg : sequence of float
        Angular positions of the excitations, degrees.
    n_max : int
        Largest wave number to check (for ``N`` equally spaced points the
        spatial Nyquist limit ``N // 2``).
    ratio : float
        Singular value ratio below which the second member counts as not driven.

    Returns
    -------
    list of int
        The wave numbers ``1..n_max`` with only one driven member.
    """
    th = np.radians(np.asarray(input_angles_deg, dtype=float).reshape(-1))
    out = []
    for n in range(1, int(n_max) + 1):
        a = np.column_stack([np.cos(n * th), np.sin(n * th)])
        sv = np.linalg.svd(a, compute_uv=False)
        if sv.size < 2 or sv[1] < ratio * sv[0]:
            out.append(n)
    return out
