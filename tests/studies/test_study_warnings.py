"""Studies print progress, not NumPy warnings: the envelope-free configurations log NaN envelopes."""
from __future__ import annotations

import warnings

from auvtrack.studies import ablation


def test_ablation_summary_of_an_envelope_free_run_is_silent():
    cfg = next(c for c in ablation.configurations() if c.label == ablation.config_label("none", "omega"))
    st = ablation.AblationSettings.quick()
    res = ablation._run(ablation._scenario(cfg, "continuous", 22.0, None, st))
    assert res.ok and not (res["rho_x"] == res["rho_x"]).any()  # envelope "none": rho is NaN throughout
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an "All-NaN slice" RuntimeWarning would fail here
        out = ablation._summary(res, st.pulse_start)
    assert out["max_widening"] is None and out["max_g"] == 0.0
