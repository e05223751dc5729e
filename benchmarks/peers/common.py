"""What every peer implementation shares: the block's constants, the scenes, the run record,
and the classification of a run's stroboscopic samples by rockjit's own compiled classifier.

The peers (``peer_nbkode.py``, ``peer_cvode.py``, ``peer_diffrax.py``) each write the rocking block
again in their library's idiom: the equations of docs/theory/model.md on either corner, the jump
``theta'(+) = e theta'(-)`` on ``theta = 0`` with ``e`` from :func:`rockjit.e_housner` /
:func:`rockjit.e_mao`, overturning at ``|theta| >= theta_over`` (``pi/2``), and the rest rule of
docs/theory/impacts.md as rockjit applies it: an impact leaving with ``|theta'| < rest_speed``
(``1e-6``) puts the block at rest, held until ``|alpha omega^2 sin(omega t + phi)| > cot(thc)``,
and the block leaves on the side of the forcing's sign. The forcing is rockjit's closed form ``r =
sin(omega t + phi)``, ``phi = atan2(r0, s0)``.

Every peer returns a :class:`PeerRun`: samples ``(theta, theta')`` at ``t = j T/2`` (``strobe``
at ``kT``, ``half`` at ``kT + T/2``) and the count of impacts up to each ``kT``, which is what
:func:`rockjit._engine.classify.classify` (the classifier behind :func:`rockjit.classify_result`
and the basin kernels) reads; :func:`label` calls it on them exactly as ``classify_result``
does, over the window ``[round(0.8 P) T, P T]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

import rockjit
from rockjit import Block, Classification, Integration, e_housner, e_mao
from rockjit._engine.classify import classify
from rockjit.result import BEHAVIOURS, OVERTURN, REST, UNRESOLVED

#: Statuses, as rockjit names them.
DONE, OVERTURNED, RESTED, MAX_IMPACTS = "done", "overturned", "rest", "max_impacts"
#: A peer's own failure (a solver error, its step bound): labelled unresolved.
FAILED = "failed"
STATUS_CODES = (DONE, OVERTURNED, RESTED, MAX_IMPACTS, FAILED)

#: rockjit's classification defaults (those of rockjit.Classification).
TOL, PMAX, LAM_TOL = Classification().tol, Classification().pmax, Classification().lam_tol

#: The work–precision scenes of benchmarks/bench_work_precision.py (same parameters, same
#: error measure: the final (theta, theta') against rockjit at N = 8192), copied here so that
#: this benchmark stands alone while the harness is restructured.
SCENES = {
    "periodic": dict(hb=1.0, alpha=0.6, omega=1.3, periods=50,
                     title="periodic: hb=1, alpha=0.6, omega=1.3, 50 periods"),
    "chaotic": dict(hb=1.0, alpha=0.955, omega=1.3, periods=5,
                    title="chaotic: hb=1, alpha=0.955, omega=1.3, 5 periods"),
}
#: The study's reference run (docs/theory/study.md, figure 2).
REFERENCE = dict(hb=1.0, alpha=0.6, omega=1.3, periods=500)
#: The study's hb=1 Housner basin (docs/theory/study.md, figure 6).
BASIN = dict(hb=1.0, alpha=0.66, omega=1.3, grid=100, periods=500, r0=0.0, s0=1.0)


@dataclass(frozen=True)
class Params:
    """The block's constants, as plain floats every peer can take.

    ``aw2 = alpha omega^2``; ``sthc, cthc = sin, cos(thc)``; ``cot = cot(thc)``; ``T`` the
    forcing period; ``phi`` the forcing phase.
    """

    hb: float
    alpha: float
    omega: float
    phi: float
    aw2: float
    thc: float
    sthc: float
    cthc: float
    xi: float
    e: float
    cot: float
    theta_over: float
    rest_speed: float
    T: float

    def vector(self):
        """The constants the compiled peers take, in a fixed order:
        ``(aw2, omega, phi, sthc, cthc, xi, e, cot, theta_over, rest_speed, T)``."""
        return np.array([self.aw2, self.omega, self.phi, self.sthc, self.cthc, self.xi,
                         self.e, self.cot, self.theta_over, self.rest_speed, self.T])


def params(hb, alpha, omega, *, law="housner", r0=None, s0=None, phi=None):
    """:class:`Params` of a block; the forcing phase from ``(r0, s0)`` (default the study's
    ``Z0_STUDY``) or ``phi``. The damping ``xi`` is rockjit's default (``rockjit.Block``),
    ``theta_over`` and ``rest_speed`` too (``rockjit.Integration``); ``e`` from
    ``rockjit.e_housner`` / ``e_mao``."""
    block = Block(hb=hb, law=law)
    integration = Integration()
    thc = math.atan(hb)
    e = float(e_housner(thc) if law == "housner" else e_mao(thc))
    if phi is None:
        if r0 is None:
            r0, s0 = rockjit.Z0_STUDY[2:]
        phi = math.atan2(r0, s0)
    return Params(hb=hb, alpha=alpha, omega=omega, phi=phi, aw2=alpha * omega**2, thc=thc,
                  sthc=math.sin(thc), cthc=math.cos(thc), xi=block.xi, e=e, cot=1.0 / hb,
                  theta_over=integration.theta_over, rest_speed=integration.rest_speed,
                  T=2.0 * math.pi / omega)


@dataclass
class PeerRun:
    """One run of a peer.

    Attributes
    ----------
    status : str
        ``done``, ``overturned``, ``rest`` (at rest for good), ``max_impacts`` or ``failed``
        (the peer's solver gave up).
    t : float
        Time reached.
    state : ndarray, shape (2,)
        ``(theta, theta')`` at ``t``.
    impacts : ndarray, shape (m,)
        Impact times (all of them), or None where the peer did not record them.
    n_impacts : int
    strobe, half : ndarray, shape (k, 2)
        ``(theta, theta')`` at ``kT`` and ``kT + T/2`` as far as the run went.
    per_imp : ndarray of int, shape (k,)
        Impacts at ``t <= kT``.
    n_rhs : int
        Right-hand-side evaluations (where the peer reports them; else -1).
    extra : dict
    """

    status: str
    t: float
    state: np.ndarray
    impacts: np.ndarray | None
    n_impacts: int
    strobe: np.ndarray
    half: np.ndarray
    per_imp: np.ndarray
    n_rhs: int = -1
    extra: dict = field(default_factory=dict)


def samples_from(n_samples, values, n_got):
    """Split the samples at ``t = j T/2`` (``values[j]``, ``j < n_got``) into ``strobe``
    (``j`` even) and ``half`` (``j`` odd)."""
    v = np.asarray(values)[:n_got]
    return v[0::2].copy(), v[1::2].copy()


def label_code(status, strobe, half, per_imp, periods, *, tol=TOL, pmax=PMAX):
    """Behaviour code of a run (an index of ``rockjit.result.BEHAVIOURS``), as
    :func:`rockjit.classify_result` finds it: overturn, rest (for good), unresolved
    (impact bound), else :func:`rockjit._engine.classify.classify` on the samples ``k0..k1`` with
    ``k0 = round(0.8 periods)`` and no Lyapunov exponent (as a basin without ``lyapunov``)."""
    if status == OVERTURNED:
        return OVERTURN
    if status == RESTED:
        return REST
    if status != DONE:
        return UNRESOLVED
    k1 = strobe.shape[0] - 1
    k0 = min(int(round(0.8 * periods)), k1)
    s4 = np.zeros((k1 + 1, 4))
    s4[:, :2] = strobe[:k1 + 1]
    h4 = np.zeros((k1 + 1, 4))
    h4[:half.shape[0], :2] = half[:k1 + 1]
    code, _ = classify(s4, h4, np.ascontiguousarray(per_imp[:k1 + 1], dtype=np.int64), k0, k1,
                       math.nan, False, float(tol), int(pmax), float(LAM_TOL))
    return int(code)


def label(run: PeerRun, periods):
    """Behaviour name of a :class:`PeerRun` (see :func:`label_code`)."""
    return BEHAVIOURS[label_code(run.status, run.strobe, run.half, run.per_imp, periods)]


def uplift_time(t, aw2, cot, omega, phi):
    """The uplift instant (docs/theory/impacts.md): the first ``t' >= t`` with
    ``|aw2 sin(omega t' + phi)| > cot`` (``inf`` if never), when a block at rest from ``t``
    lifts off."""
    if aw2 <= cot:
        return math.inf
    a = math.asin(cot / aw2)
    psi = omega * t + phi
    u = psi - math.pi * math.floor(psi / math.pi)
    if a < u < math.pi - a:
        return t
    if u <= a:
        return t + (a - u) / omega
    return t + (math.pi - u + a) / omega


def basin_axes(grid=BASIN["grid"]):
    """The study's basin lattice: ``theta0`` and ``theta0'`` on ``linspace(-1, 1, grid)``."""
    return np.linspace(-1.0, 1.0, grid), np.linspace(-1.0, 1.0, grid)
