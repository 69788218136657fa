"""Theorem 1 of the paper: its gain conditions and its fixed-time bounds, corrected.

Three things live here (derivations in ``docs/theory.md``; equation numbers are the paper's):

* :func:`check_theorem1` / :func:`require_theorem1`: the conditions of Theorem 1 on the
  ``[controller]`` gains of :class:`~auvtrack.control.fxtntsmc.Params`.
* :func:`lemma1_time` / :func:`lemma1_residual`: Lemma 1 (eq. 6-7) as corrected by ERRATA 15,
  for ``V_dot <= -m1 V^m2 - n1 V^n2 + m3`` with ``0 < m2 < 1 < n2`` and ``0 < gamma1 < 1``.
* :func:`fixed_time_bounds`: T1 (43), T21 (48), T22 (52), the residual set (44) and mu1, mu2,
  returned as a :class:`FixedTimeBounds` that says plainly when the guarantee is *vacuous*.

Corrections to the proof applied here (each derived in ``docs/theory.md``):

1. Lemma 1: ``1 - n2`` -> ``n2 - 1`` in (6), exponent ``1/m4`` -> ``1/n2`` in (7) (ERRATA 15).
2. zeta2 of (42): the step from sum |x_j|^2 to V^2 needs Lemma 3 (10) with n = 6 terms, which
   gives zeta2 = (2/3) min{kappa2, c}; the printed min{4 kappa2, 4 c} is 6 times too large.
   Both are reported; T1 uses the corrected one.
3. (51) drops beta2 = (alpha - 1) sigma^(alpha-2), negative for alpha < 1.  On 0 <= S_e <= sigma,
   beta1 S_e + beta2 S_e^2 >= min(beta1, beta1 + beta2 sigma) S_e = min(1, 2 - alpha) sigma^(alpha-1) S_e,
   so T22 uses that slope instead of beta1 (for alpha < 1 it is sigma^(alpha-1)).
4. T2: z crosses the outer region (S_e > sigma, time <= T21) and *then* the inner one
   (S_e <= sigma, time <= T22); the phases are sequential, so T2 = T21 + T22.  The printed
   T2 = max{T21, T22} is reported for comparison only: it is exceeded on the sliding manifold
   S = 0 for admissible gains (``tests/control/test_theory.py``).

The lam1, lam2 of (39)-(42) are free Young-inequality constants of the proof, NOT the envelope
gains lambda1, lambda2 of eq. (25) that share the name; here they are ``lam1``, ``lam2``.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

from scipy.optimize import brentq

from . import switch_coeffs

__all__ = [
    "FixedTimeBounds",
    "TheoremConditionError",
    "check_theorem1",
    "fixed_time_bounds",
    "lemma1_residual",
    "lemma1_time",
    "require_theorem1",
    "switch_slope",
    "t21_bound",
    "t22_bound",
]

PREFIX = "controller."  # scenario section of the gains
GAIN_KEYS = ("kappa1", "kappa2", "kappa3", "a1", "a2", "a3", "a4", "alpha", "sigma", "varsigma1")
INF = math.inf
ENVELOPE_FRACTION = 0.99  # a residual |e| <= 0.99 rho or more guarantees (almost) nothing
KAPPA2_CAP = 1.0 - 1e-3  # c < 1 always: if kappa2 >= 1, aim within 0.1 % of c's supremum 1


class TheoremConditionError(ValueError):
    """The gains violate at least one condition of Theorem 1."""


# --------------------------------------------------------------------------- conditions

_Cond = tuple[str, tuple[str, ...], Callable[..., bool], str]
# (condition as written with scenario keys, keys involved, predicate, paper's spelling or "")
_CONDITIONS: tuple[_Cond, ...] = (
    ("kappa1 > 0", ("kappa1",), lambda k: k > 0, ""),
    ("kappa2 > 0", ("kappa2",), lambda k: k > 0, ""),
    ("kappa3 > 0.5", ("kappa3",), lambda k: k > 0.5, ""),
    ("a1 > 0", ("a1",), lambda a: a > 0, ""),
    ("a3 > 0", ("a3",), lambda b: b > 0, "b1 > 0"),
    ("0.5 <= a2 < 1", ("a2",), lambda a: 0.5 <= a < 1, ""),
    ("a4 > 1", ("a4",), lambda b: b > 1, "b2 > 1"),
    ("alpha > 0.5", ("alpha",), lambda a: a > 0.5, ""),
    ("a2*alpha < 1", ("a2", "alpha"), lambda a, al: a * al < 1, ""),
    ("a4*alpha > 1", ("a4", "alpha"), lambda b, al: b * al > 1, "b2*alpha > 1"),
    ("sigma > 0", ("sigma",), lambda s: s > 0, ""),
    ("varsigma1 > 0", ("varsigma1",), lambda s: s > 0, "varsigma1 > 0, printed 'zeta1' in Section 4"),
)


def _gains(params: Any) -> dict[str, float]:
    """The ten gains of ``params`` (model, any object with the attributes, or a mapping)."""
    get = params.get if isinstance(params, Mapping) else lambda k: getattr(params, k, None)
    out = {}
    for k in GAIN_KEYS:
        v = get(k)
        if v is None:
            raise TypeError(f"{PREFIX}{k} is missing: Theorem 1 needs the fxtntsmc gains {GAIN_KEYS}")
        out[k] = float(v)
    return out


def check_theorem1(params: Any) -> list[str]:
    """List the conditions of Theorem 1 that the gains violate.

    Parameters
    ----------
    params : auvtrack.control.fxtntsmc.Params or Mapping[str, float]
        The controller gains, by scenario key (``a3`` is the theorem's b1, ``a4`` its b2,
        ``varsigma1`` its approximation-error bound).  Unvalidated values (e.g. built with
        ``model_copy(update=...)``) are accepted.

    Returns
    -------
    list of str
        One message per violated condition, e.g.
        ``"controller.kappa3 = 0.4 violates kappa3 > 0.5 (Theorem 1)"``; empty if all hold.
        NaN violates every condition it appears in.
    """
    g = _gains(params)
    out = []
    for text, keys, pred, paper in _CONDITIONS:
        vals = [g[k] for k in keys]
        if pred(*vals):
            continue
        named = ", ".join(f"{PREFIX}{k} = {v!r}" for k, v in zip(keys, vals))
        verb = "violates" if len(keys) == 1 else "violate"
        extra = [paper] if paper else []
        if len(keys) == 2:
            extra.append(f"{keys[0]}*{keys[1]} = {vals[0] * vals[1]!r}")
        note = "Theorem 1" + (": " + "; ".join(extra) if extra else "")
        out.append(f"{named} {verb} {text} ({note})")
    return out


def require_theorem1(params: Any) -> None:
    """Raise :class:`TheoremConditionError` unless every condition of Theorem 1 holds.

    Parameters
    ----------
    params : auvtrack.control.fxtntsmc.Params or Mapping[str, float]
        The controller gains.

    Raises
    ------
    TheoremConditionError
        One-line message listing every violated condition, joined by ``"; "``.
    """
    bad = check_theorem1(params)
    if bad:
        raise TheoremConditionError("; ".join(bad))


# --------------------------------------------------------------------------- Lemma 1

def _check_lemma1(m1: float, m2: float, n1: float, n2: float, gamma1: float) -> None:
    if not (m1 > 0 and n1 > 0):
        raise ValueError(f"Lemma 1 needs m1 > 0 and n1 > 0 (got m1 = {m1!r}, n1 = {n1!r})")
    if not (0 < m2 < 1 < n2):
        raise ValueError(f"Lemma 1 needs 0 < m2 < 1 < n2 (got m2 = {m2!r}, n2 = {n2!r})")
    if not 0 < gamma1 < 1:
        raise ValueError(f"Lemma 1 needs 0 < gamma1 < 1 (got {gamma1!r})")


def lemma1_time(m1: float, m2: float, n1: float, n2: float, gamma1: float) -> float:
    """Settling-time bound of Lemma 1, eq. (6) corrected (ERRATA 15).

    For ``V_dot <= -m1 V^m2 - n1 V^n2 + m3``, V enters the residual set of
    :func:`lemma1_residual` within

        T <= 1 / (m1 gamma1 (1 - m2)) + 1 / (n1 gamma1 (n2 - 1))

    from any V(0): outside the set V_dot <= -gamma1 (m1 V^m2 + n1 V^n2); integrate with the
    m-term on V <= 1 and the n-term on V >= 1.

    Parameters
    ----------
    m1 : float
        Positive gain of the ``V^m2`` term.
    m2 : float
        Exponent, ``0 < m2 < 1``.
    n1 : float
        Positive gain of the ``V^n2`` term.
    n2 : float
        Exponent, ``n2 > 1``.
    gamma1 : float
        Free constant of the lemma, ``0 < gamma1 < 1``.

    Returns
    -------
    float
        The bound T, in the time unit of the inequality.

    Raises
    ------
    ValueError
        If an argument is outside its range.
    """
    _check_lemma1(m1, m2, n1, n2, gamma1)
    return 1.0 / (m1 * gamma1 * (1.0 - m2)) + 1.0 / (n1 * gamma1 * (n2 - 1.0))


def lemma1_residual(m1: float, m2: float, n1: float, n2: float, m3: float, gamma1: float) -> float:
    """Residual set of Lemma 1, eq. (7) corrected (ERRATA 15).

    The set is ``V <= R`` with

        R = min{ [m3 / (m1 (1 - gamma1))]^(1/m2), [m3 / (n1 (1 - gamma1))]^(1/n2) }.

    Parameters
    ----------
    m1, m2, n1, n2 : float
        As in :func:`lemma1_time`.
    m3 : float
        Non-negative constant term of the inequality.
    gamma1 : float
        As in :func:`lemma1_time`.

    Returns
    -------
    float
        R; V stays in ``V <= R`` once there, since V_dot < 0 on ``V > R``.

    Raises
    ------
    ValueError
        If an argument is outside its range.
    """
    _check_lemma1(m1, m2, n1, n2, gamma1)
    if not m3 >= 0:
        raise ValueError(f"Lemma 1 needs m3 >= 0 (got {m3!r})")
    return min((m3 / (m1 * (1.0 - gamma1))) ** (1.0 / m2), (m3 / (n1 * (1.0 - gamma1))) ** (1.0 / n2))


# --------------------------------------------------------------------------- phase 2

def switch_slope(alpha: float, sigma: float) -> float:
    """Least slope of the switch (27) on ``0 < S_e <= sigma``: min over S_e of S1(S_e) / S_e.

    ``S1 / S_e = beta1 + beta2 S_e`` is monotone, so the minimum is at an end:
    ``min(beta1, beta1 + beta2 sigma) = min(1, 2 - alpha) sigma^(alpha - 1)``; for
    ``alpha < 1`` (beta2 < 0) this is sigma^(alpha-1), not the beta1 that (51) uses.

    Parameters
    ----------
    alpha, sigma : float
        Gains of eq. (27), ``sigma > 0``.

    Returns
    -------
    float
        The slope (non-positive when alpha >= 2: no decay near S_e = 0).
    """
    return min(1.0, 2.0 - alpha) * sigma ** (alpha - 1.0)


def t21_bound(a1: float, a2: float, a3: float, a4: float, alpha: float, g1: float) -> float:
    """T21 of eq. (48): ``(1/g1) (1/(a1^alpha (1 - a2 alpha)) + 1/(a3^alpha (a4 alpha - 1)))``.

    Bounds the time of ``z_dot = -g1 (a1 z^a2 + a3 z^a4)^alpha`` from any z(0) to 0; the last
    step of (48) uses ``(1 - a2 alpha)(lam alpha - 1) = a4 alpha - 1``, lam = (a4 - a2)/(1 - a2 alpha).

    Returns
    -------
    float
        The bound in seconds; ``inf`` if ``a2 alpha >= 1``, ``a4 alpha <= 1`` or a gain is <= 0.
    """
    if not (a1 > 0 and a3 > 0 and g1 > 0 and a2 * alpha < 1 < a4 * alpha):
        return INF
    return (1.0 / g1) * (1.0 / (a1**alpha * (1.0 - a2 * alpha)) + 1.0 / (a3**alpha * (a4 * alpha - 1.0)))


def t22_bound(a1: float, a2: float, a3: float, a4: float, alpha: float, sigma: float, g2: float,
              *, printed: bool = False) -> float:
    """T22 of eq. (52): ``(1/(g2 beta)) (1/(a1 (1 - a2)) + 1/(a3 (a4 - 1)))``.

    Parameters
    ----------
    a1, a2, a3, a4, alpha, sigma : float
        Gains of eq. (27)-(28).
    g2 : float
        Tuning constant of eq. (50), in (0, 1).
    printed : bool
        False (default): beta = :func:`switch_slope` (corrected (51)).  True: beta = beta1 =
        (2 - alpha) sigma^(alpha-1) as printed, which is not a valid bound for alpha < 1.

    Returns
    -------
    float
        The bound in seconds; ``inf`` where the derivation breaks down (a2 >= 1, a4 <= 1,
        beta <= 0 or a gain <= 0).
    """
    if not (a1 > 0 and a3 > 0 and g2 > 0 and sigma > 0 and a2 < 1 < a4):
        return INF
    beta = switch_coeffs.py_func(alpha, sigma)[0] if printed else switch_slope(alpha, sigma)
    if not beta > 0:
        return INF
    return (1.0 / (g2 * beta)) * (1.0 / (a1 * (1.0 - a2)) + 1.0 / (a3 * (a4 - 1.0)))


# --------------------------------------------------------------------------- lam1, lam2

def _young_c(lam1: float, lam2: float) -> float:
    """Coefficient of |W~|^4 in (42): c = 1 - (9/4) lam1^(4/3) - 1/(4 lam2^4)."""
    return 1.0 - 2.25 * lam1 ** (4.0 / 3.0) - 0.25 / lam2**4


def _young_k(lam1: float, lam2: float) -> float:
    """Coefficient of |W_bar|^4 in zeta3: k = (3/4) lam2^(4/3) + 3/(4 lam1^4)."""
    return 0.75 * lam2 ** (4.0 / 3.0) + 0.75 / lam1**4


def _choose_lams(kappa2: float, lam1: float | None, lam2: float | None) -> tuple[float, float, str]:
    """Pick the free proof constants lam1, lam2 of (39)-(40).

    zeta2 depends on them only through min{kappa2, c}: aim at c = min(kappa2, KAPPA2_CAP) and,
    of the pairs reaching it, take the one with the least zeta3 coefficient k (the stationary
    point of k on the budget (9/4) lam1^(4/3) + 1/(4 lam2^4) = 1 - c has lam2 = 1/lam1).
    A given constant is kept and only the other one chosen.
    """
    if lam1 is not None and lam2 is not None:
        return lam1, lam2, "given"
    target = min(kappa2, KAPPA2_CAP) if kappa2 > 0 else KAPPA2_CAP
    budget = 1.0 - target
    if lam1 is None and lam2 is None:
        lam = brentq(lambda x: 2.25 * x ** (4.0 / 3.0) + 0.25 * x**4 - budget, 0.0, 10.0, xtol=1e-15)
        return lam, 1.0 / lam, f"chosen: c = {target:g} with least zeta3"
    if lam1 is not None:
        used = 2.25 * lam1 ** (4.0 / 3.0)
        rest = budget - used if budget > used else 1e-3 * max(1.0 - used, 0.0)
        return lam1, ((4.0 * rest) ** -0.25 if rest > 0 else 1.0), "lam1 given, lam2 chosen"
    used = 0.25 / lam2**4  # type: ignore[operator]
    rest = budget - used if budget > used else 1e-3 * max(1.0 - used, 0.0)
    return (rest / 2.25) ** 0.75 if rest > 0 else 1.0, lam2, "lam2 given, lam1 chosen"  # type: ignore[return-value]


# --------------------------------------------------------------------------- the bounds

def _se(z: float, a1: float, a2: float, a3: float, a4: float) -> float:
    """S_e(z) of eq. (28) as printed, for z >= 0 (z dimensionless), for root finding.

    Scalar Python form of :func:`auvtrack.control.fxtntsmc.surface` with ``printed`` (pinned to
    it in ``tests/control/test_theory.py``), which is NaN at z = 0 (it forms z^(a2-1)); this one is 0 there.
    """
    return a1 * z**a2 + a3 * z**a4


def _z_of_se(target: float, a1: float, a2: float, a3: float, a4: float) -> float:
    """The z >= 0 with S_e(z) = target (S_e is increasing)."""
    hi = 1.0
    while _se(hi, a1, a2, a3, a4) < target:
        hi *= 2.0
    return brentq(lambda z: _se(z, a1, a2, a3, a4) - target, 0.0, hi, xtol=1e-300, rtol=1e-14)


def _fmt(x: float | None, unit: str = "") -> str:
    if x is None:
        return "unknown"
    if math.isinf(x):
        return "inf"
    return f"{x:.6g}{unit}"


def _json(x: Any) -> Any:
    """JSON-safe copy: +-inf -> "inf"/"-inf", NaN -> "nan"; None stays None (= unknown)."""
    if isinstance(x, float) and not math.isfinite(x):
        return "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf")
    if isinstance(x, dict):
        return {k: _json(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_json(v) for v in x]
    return x


@dataclass
class FixedTimeBounds:
    """Theorem 1's fixed-time bounds for one set of gains (see :func:`fixed_time_bounds`).

    Times are in seconds.  ``None`` means "not computable from the inputs" (typically: needs the
    unknown ideal-weight norm ``w_norm``); ``inf`` means the bound is infinite.

    Attributes
    ----------
    gains : dict
        The ten gains, by scenario key.
    gamma1, g1, g2, lam1, lam2 : float
        Proof constants used (lam1, lam2: Young constants of (39)-(40), not the envelope gains).
    lam_choice : str
        How lam1, lam2 were obtained.
    w_norm : list of 3 floats or None
        Ideal-weight norms |W_bar_i| per axis (zeta1 uses the least); None if unknown.
    horizon : float or None
        Time span the guarantee is compared with (e.g. the simulation duration).
    violations : list of str
        Violated conditions of Theorem 1 (:func:`check_theorem1`).
    zeta1, zeta2, zeta2_printed, zeta3 : float or None
        Constants of (42).  zeta1 is the best case sqrt(2) kappa1 when ``w_norm`` is None;
        zeta2 has the Lemma 3 factor corrected, zeta2_printed is the paper's
        min{4 kappa2, 4 - 9 lam1^(4/3) - 1/lam2^4}; zeta3 needs ``w_norm``.
    T1, T1_printed : float
        Bound (43) with zeta2, resp. zeta2_printed.
    T1_is_lower_bound : bool
        True when ``w_norm`` is unknown: the true zeta1 can only be smaller, so the
        guaranteed T1 can only be larger than the number given.
    beta1, beta2, beta_eff : float
        Coefficients of the switch (27) and the corrected slope used in T22.
    T21, T22, T22_printed : float
        Bounds (48), (52) corrected, (52) as printed.
    T2, T2_printed : float
        T21 + T22 (sequential phases), and the paper's max{T21, T22} for comparison.
    T : float
        T1 + T2.
    Lambda : float or None
        Residual set (44) of V (needs zeta3).
    p, mu1, mu2, z_sigma, mu : float or None
        Bound on |S_i| after T1 (sqrt(2 Lambda) unless given), the residual boundaries of z
        defined below (45) and (49), the z where S_e = sigma, and the resulting residual
        ``|z| <= mu`` (mu1 if mu1 > z_sigma, else mu2), i.e. ``|e| <= tanh(mu) rho``.
    vacuous : bool
        True when a condition fails, a bound is infinite, or T exceeds ``horizon``.
    reasons : list of str
        Why the guarantee is vacuous (empty otherwise).
    notes : list of str
        Caveats that do not by themselves make the guarantee vacuous.
    """

    gains: dict[str, float]
    gamma1: float
    g1: float
    g2: float
    lam1: float
    lam2: float
    lam_choice: str
    w_norm: list[float] | None
    horizon: float | None
    violations: list[str]
    zeta1: float
    zeta2: float
    zeta2_printed: float
    zeta3: float | None
    T1: float
    T1_printed: float
    T1_is_lower_bound: bool
    beta1: float
    beta2: float
    beta_eff: float
    T21: float
    T22: float
    T22_printed: float
    T2: float
    T2_printed: float
    T: float
    Lambda: float | None
    p: float | None
    mu1: float | None
    mu2: float | None
    z_sigma: float | None
    mu: float | None
    vacuous: bool
    reasons: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe dict (``json.dumps(..., allow_nan=False)`` works): inf -> ``"inf"``."""
        return _json(asdict(self))

    def report(self) -> str:
        """Short plain-text report for ``auvtrack bounds SCENARIO``."""
        g = self.gains
        lb = ">=" if self.T1_is_lower_bound else "<="
        lines = [
            "Theorem 1 fixed-time bounds (corrected; docs/theory.md)",
            "gains: " + " ".join(f"{k}={g[k]:g}" for k in GAIN_KEYS) + "   (a3 = b1, a4 = b2)",
            f"proof constants: gamma1={self.gamma1:g} g1={self.g1:g} g2={self.g2:g} "
            f"lam1={self.lam1:.4g} lam2={self.lam2:.4g} ({self.lam_choice}; Young constants of (39)-(40), "
            "not the envelope gains) ideal-weight norm="
            + ("unknown" if self.w_norm is None else ", ".join(f"{w:g}" for w in self.w_norm)),
            "Theorem 1 conditions: " + ("all hold" if not self.violations else "; ".join(self.violations)),
            f"zeta1 = {_fmt(self.zeta1)}  (42) min{{sqrt2 kappa1, 2 sqrt2 |W|^2}}"
            + ("  [best case sqrt2 kappa1: |W| unknown]" if self.w_norm is None else ""),
            f"zeta2 = {_fmt(self.zeta2)}  (42) (2/3) min{{kappa2, c}}, Lemma 3 factor corrected "
            f"(printed: {_fmt(self.zeta2_printed)})",
            f"zeta3 = {_fmt(self.zeta3)}  (42) varsigma1^2/2 + sum(|W|^2 + k |W|^4)",
            f"T1  {lb} {_fmt(self.T1, ' s')}  (43) 2/(zeta1 gamma1) + 1/(zeta2 gamma1)"
            + ("  [LOWER BOUND on the guaranteed T1]" if self.T1_is_lower_bound else "")
            + f"  (with printed zeta2: {_fmt(self.T1_printed, ' s')})",
            f"T21 <= {_fmt(self.T21, ' s')}  (48) (1/g1)(1/(a1^alpha (1-a2 alpha)) + 1/(b1^alpha (b2 alpha-1)))",
            f"T22 <= {_fmt(self.T22, ' s')}  (52) corrected: beta1 -> {_fmt(self.beta_eff)} "
            f"(printed with beta1 = {_fmt(self.beta1)}: {_fmt(self.T22_printed, ' s')})",
            f"T2  <= {_fmt(self.T2, ' s')}  T21 + T22, sequential phases "
            f"(printed max{{T21, T22}} = {_fmt(self.T2_printed, ' s')} is not a valid bound)",
            f"T   {lb} {_fmt(self.T, ' s')}  T1 + T2",
            f"residual set (44): V <= {_fmt(self.Lambda)};  |S_i| <= p = {_fmt(self.p)};  "
            f"mu1 = {_fmt(self.mu1)}, mu2 = {_fmt(self.mu2)}, S_e = sigma at z = {_fmt(self.z_sigma)};  "
            f"|z| <= mu = {_fmt(self.mu)}",
        ]
        if self.horizon is not None:
            lines.append(f"horizon: {self.horizon:g} s")
        lines += [f"note: {n}" for n in self.notes]
        if self.vacuous:
            lines.append("VACUOUS: " + "; ".join(self.reasons))
        elif self.T1_is_lower_bound:
            lines.append("NOT CERTIFIED: T1 is only a lower bound because the ideal-weight norm is unknown")
        else:
            lines.append(f"OK: |z| <= mu = {_fmt(self.mu)} (|e| <= {_fmt(math.tanh(self.mu) if self.mu is not None else None)}"
                         f" rho) within T <= {_fmt(self.T, ' s')}")
        return "\n".join(lines)


def _norms(w_norm: float | Sequence[float] | None) -> list[float] | None:
    if w_norm is None:
        return None
    ws = [float(w_norm)] * 3 if isinstance(w_norm, (int, float)) else [float(w) for w in w_norm]
    if len(ws) != 3 or not all(w >= 0 for w in ws):
        raise ValueError(f"w_norm must be a norm >= 0 or three of them (one per axis), got {w_norm!r}")
    return ws


def fixed_time_bounds(
    params: Any,
    *,
    gamma1: float = 0.5,
    g1: float = 0.5,
    g2: float = 0.5,
    lam1: float | None = None,
    lam2: float | None = None,
    w_norm: float | Sequence[float] | None = None,
    horizon: float | None = None,
    p: float | None = None,
) -> FixedTimeBounds:
    """Evaluate Theorem 1's fixed-time bounds (43), (48), (52) for the gains ``params``.

    Parameters
    ----------
    params : auvtrack.control.fxtntsmc.Params or Mapping[str, float]
        The controller gains.
    gamma1 : float
        Lemma 1 constant, in (0, 1).
    g1, g2 : float
        Tuning constants of (45) and (50), in (0, 1).
    lam1, lam2 : float, optional
        Young constants of (39)-(40) (not the envelope gains); chosen if not given so that
        zeta2 is as large as possible, then zeta3 as small as possible.
    w_norm : float or sequence of 3 floats, optional
        Norm(s) |W_bar_i| of the unknown ideal RBF weights.  If None, zeta1 takes its best
        case sqrt(2) kappa1, so T1 is a LOWER bound on the guaranteed T1, and zeta3, the
        residual set (44), p and mu1/mu2 are not computable.
    horizon : float, optional
        Time span to compare T with (e.g. the simulation duration); T > horizon is vacuous.
    p : float, optional
        Bound on |S_i| after T1 used for mu1, mu2; default sqrt(2 Lambda) when computable.

    Returns
    -------
    FixedTimeBounds
        All numbers, with ``vacuous`` and ``reasons`` stating plainly when the guarantee says
        nothing (a condition fails, a bound is infinite, or it exceeds ``horizon``).

    Raises
    ------
    ValueError
        If a proof constant is outside its range (gamma1, g1, g2 in (0, 1); lam1, lam2 > 0;
        w_norm >= 0; horizon > 0; p >= 0).
    """
    for name, v in (("gamma1", gamma1), ("g1", g1), ("g2", g2)):
        if not 0 < v < 1:
            raise ValueError(f"{name} must lie in (0, 1), got {v!r}")
    for name, v in (("lam1", lam1), ("lam2", lam2)):
        if v is not None and not v > 0:
            raise ValueError(f"{name} (a Young constant of (39)-(40)) must be > 0, got {v!r}")
    if horizon is not None and not horizon > 0:
        raise ValueError(f"horizon must be > 0, got {horizon!r}")
    if p is not None and not p >= 0:
        raise ValueError(f"p must be >= 0, got {p!r}")
    ws = _norms(w_norm)
    gn = _gains(params)
    k1, k2, s1 = gn["kappa1"], gn["kappa2"], gn["varsigma1"]
    a1, a2, a3, a4, al, sg = (gn[k] for k in ("a1", "a2", "a3", "a4", "alpha", "sigma"))
    violations = check_theorem1(gn)
    reasons = [f"Theorem 1 does not apply: {v}" for v in violations]
    notes: list[str] = []

    # --- phase 1: (42)-(44)
    l1, l2, how = _choose_lams(k2, lam1, lam2)
    c = _young_c(l1, l2)
    zeta1 = math.sqrt(2.0) * k1 if ws is None else min(math.sqrt(2.0) * k1, 2.0 * math.sqrt(2.0) * min(ws) ** 2)
    zeta2 = (2.0 / 3.0) * min(k2, c)
    zeta2_printed = min(4.0 * k2, 4.0 * c)
    zeta3 = None if ws is None else 0.5 * s1**2 + sum(w**2 + _young_k(l1, l2) * w**4 for w in ws)

    def t1_of(z2: float) -> float:
        return lemma1_time(zeta1, 0.5, z2, 2.0, gamma1) if zeta1 > 0 and z2 > 0 else INF

    T1, T1_printed = t1_of(zeta2), t1_of(zeta2_printed)
    if not zeta1 > 0:
        reasons.append(f"zeta1 = min{{sqrt2 kappa1, 2 sqrt2 |W|^2}} = {zeta1:g} <= 0: the V^(1/2) term of "
                       "(42) vanishes and T1 (43) is infinite")
    if not c > 0:
        reasons.append(f"with lam1 = {l1:g}, lam2 = {l2:g}, 4 - 9 lam1^(4/3) - 1/lam2^4 = {4 * c:g} <= 0: "
                       "the V^2 term of (42) has no decay and T1 (43) is infinite")
    elif not k2 > 0:
        reasons.append(f"kappa2 = {k2:g} <= 0 makes zeta2 <= 0: T1 (43) is infinite")
    if ws is None:
        notes.append("ideal-weight norm unknown: zeta1 = sqrt2 kappa1 is its best case, so T1 is a LOWER "
                     "bound on the guaranteed T1; zeta3, the residual set (44), p, mu1 and mu2 need w_norm")
    if k2 >= 1 and (lam1 is None or lam2 is None):
        notes.append("kappa2 >= 1: c < 1 always, so lam1, lam2 were chosen to bring c within 0.1 % of 1")
    Lam = None
    if zeta3 is not None and zeta1 > 0 and zeta2 > 0:
        Lam = lemma1_residual(zeta1, 0.5, zeta2, 2.0, zeta3, gamma1)
    if p is None and Lam is not None:
        p = math.sqrt(2.0 * Lam)  # |S_i|^2 / 2 <= V

    # --- phase 2: (45)-(54)
    beta1, beta2 = switch_coeffs.py_func(al, sg) if sg > 0 else (math.nan, math.nan)
    beta_eff = switch_slope(al, sg) if sg > 0 else math.nan
    T21 = t21_bound(a1, a2, a3, a4, al, g1)
    T22 = t22_bound(a1, a2, a3, a4, al, sg, g2)
    T22_printed = t22_bound(a1, a2, a3, a4, al, sg, g2, printed=True)
    T2, T2_printed, T = T21 + T22, max(T21, T22), T1 + T21 + T22
    if math.isinf(T21):
        reasons.append("T21 (48) is infinite: it needs a1, b1 > 0, a2 alpha < 1 < b2 alpha")
    if math.isinf(T22):
        reasons.append("T22 (52) is infinite: it needs a1, b1, sigma > 0, a2 < 1 < b2 and a positive "
                       "switch slope min(1, 2 - alpha) sigma^(alpha-1)")
    if al < 1 and sg > 0:
        notes.append(f"(51) drops beta2 = {beta2:.4g} < 0: T22 uses the slope sigma^(alpha-1) = {beta_eff:.4g} "
                     f"instead of beta1 = {beta1:.4g}")
    z_sigma = mu1 = mu2 = None
    good_surface = a1 > 0 and a3 > 0 and 0 < a2 < 1 < a4 and sg > 0
    if good_surface:
        z_sigma = _z_of_se(sg, a1, a2, a3, a4)
    if p is not None and good_surface and al > 0:
        # (1 - g1) S_e(mu1)^alpha = p and (1 - g2) S1(S_e(mu2)) = p, S1 = beta1 s + beta2 s^2 on s <= sigma
        mu1 = _z_of_se((p / (1.0 - g1)) ** (1.0 / al), a1, a2, a3, a4) if p > 0 else 0.0
        q = p / (1.0 - g2)
        if q >= sg**al:
            mu2 = z_sigma
            notes.append("p/(1 - g2) >= sigma^alpha: the whole inner region S_e <= sigma lies in the residual "
                         "neighbourhood, mu2 := z at S_e = sigma")
        elif q == 0:
            mu2 = 0.0
        else:
            s_mu = brentq(lambda s: beta1 * s + beta2 * s * s - q, 0.0, sg, xtol=1e-300, rtol=1e-14)
            mu2 = _z_of_se(s_mu, a1, a2, a3, a4)
    mu = None
    if mu1 is not None and mu2 is not None and z_sigma is not None:
        mu = mu1 if mu1 > z_sigma else mu2
        if math.tanh(mu) >= ENVELOPE_FRACTION:
            reasons.append(f"the residual |z| <= mu = {mu:.4g} means |e| <= tanh(mu) rho = {math.tanh(mu):.6f} rho: "
                           "the residual set is (almost) the whole envelope, so the accuracy guarantee says nothing")
    surface = params.get("surface") if isinstance(params, Mapping) else getattr(params, "surface", None)
    if surface == "nonsingular":
        zsw = params.get("z_switch") if isinstance(params, Mapping) else getattr(params, "z_switch", None)
        notes.append(f"surface 'nonsingular': S_e differs from (28) for |z| <= z_switch = {zsw:g}; the phase-2 "
                     "bounds cover reaching |z| <= z_switch, inside which convergence is exponential, not fixed-time")

    # --- verdict
    if horizon is not None and math.isfinite(T) and T > horizon:
        lower = " (itself only a lower bound)" if ws is None else ""
        if T1 > horizon:
            what = f"the bound T1 = {T1:.6g} s{lower} alone"
        elif T2 > horizon:
            what = f"the bound T2 = {T2:.6g} s alone"
        else:
            what = f"the bound T = T1 + T2 = {T:.6g} s{lower}"
        reasons.append(f"{what} exceeds the horizon {horizon:g} s: the fixed-time guarantee says nothing "
                       "within it")
    if zeta1 > 0 and math.isfinite(T1) and 2.0 / (zeta1 * gamma1) > 0.9 * T1:
        notes.append(f"T1 is dominated by 2/(zeta1 gamma1): T1 > 2/zeta1 = {2.0 / zeta1:.4g} s for every gamma1 "
                     "in (0, 1)" + (" (zeta1 = sqrt2 kappa1: a small switching gain kappa1 makes T1 long)"
                                    if zeta1 == math.sqrt(2.0) * k1 else " (zeta1 set by the ideal-weight norm)"))
    vacuous = bool(reasons)
    return FixedTimeBounds(
        gains=gn, gamma1=gamma1, g1=g1, g2=g2, lam1=l1, lam2=l2, lam_choice=how,
        w_norm=ws, horizon=horizon, violations=violations,
        zeta1=zeta1, zeta2=zeta2, zeta2_printed=zeta2_printed, zeta3=zeta3,
        T1=T1, T1_printed=T1_printed, T1_is_lower_bound=ws is None,
        beta1=beta1, beta2=beta2, beta_eff=beta_eff, T21=T21, T22=T22, T22_printed=T22_printed,
        T2=T2, T2_printed=T2_printed, T=T, Lambda=Lam, p=p, mu1=mu1, mu2=mu2, z_sigma=z_sigma, mu=mu,
        vacuous=vacuous, reasons=reasons, notes=notes,
    )
