"""The gate threshold through the incomplete gamma function is scipy's χ² quantile, bit for bit."""

from __future__ import annotations

import numpy as np
from scipy.stats import chi2

from core.tracking.gating import gate_threshold


def test_gate_threshold_is_the_chi_square_quantile_exactly() -> None:
    for p_g in np.linspace(0.5, 0.99999, 401):
        for dof in (2, 3, 4):
            assert gate_threshold(float(p_g), dof) == float(chi2.ppf(p_g, dof))
    # a value to check by hand: χ²⁻¹_2(p) = −2 ln(1 − p), so p = 1 − e⁻³ gives γ = 6
    assert abs(gate_threshold(1.0 - np.exp(-3.0), 2) - 6.0) < 1e-12
