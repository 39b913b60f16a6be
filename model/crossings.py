"""What a threshold search returns: the crossings of the max growth in gamma or eta (:class:`Crossings`) and what
their reason codes mean (:class:`CrossingReason`, :class:`ThresholdReason`), shared by the Rayleigh branch's solver
(:mod:`model.thresholds`) and the sliding one over every branch (``model._sliding_thresholds``). docs/physics.md
§9, §14.10.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

import numpy as np

SCAN_POINTS = 17  # log-spaced scan values of the search range
MAX_CROSSINGS = 4  # crossings returned per parameter set (the count may be larger)


class CrossingReason(IntEnum):
    """Whether a sign change of the max growth is a threshold, and why not (Crossings.reason; atlases'
    ``gamma_c_crossing_reason``): the keys of :data:`CROSSING_STATUS`."""

    CERTIFIED = 0
    EDGE = 1
    JUMP_MASKED = 2
    JUMP = 3
    POLE_DENSE = 4
    UNDEFINED = 5
    NOT_CERTIFIED = 6


X_CERTIFIED, X_EDGE, X_JUMP_MASKED, X_JUMP, X_POLE_DENSE, X_UNDEFINED, X_NOT_CERTIFIED = CrossingReason
#: the reasons of a certified crossing, a threshold: a neutral mode, or one at an end of the kH range
CERTIFIED_CROSSINGS = (CrossingReason.CERTIFIED, CrossingReason.EDGE)
#: what the reason codes of a crossing mean (Crossings.reason; atlases' ``gamma_c_crossing_reason``)
CROSSING_STATUS = {
    X_CERTIFIED: "certified: a neutral mode (real z, Im z stationary in kH) on the Rayleigh branch where the max "
    "growth changes sign",
    X_EDGE: "certified at an end of the kH range: the max growth over the range is at its end there (Im z = 0 at "
    "that kH; over a wider range the maximum, and so the threshold, may lie elsewhere)",
    X_JUMP_MASKED: "jump, not a threshold: the max growth jumps across zero where the part of the kH range on which "
    "the Rayleigh branch is followed changes",
    X_JUMP: "jump, not a threshold: the max growth jumps across zero with the branch followed on both sides (the "
    "continuation changes route, or the pole-dense part of the range changes): no neutral mode",
    X_POLE_DENSE: "pole-dense: the neutral mode lies among the lower block's poles (finite eta, |Re z| > 1)",
    X_UNDEFINED: "undefined: the max growth is NaN (no certified root) inside the bracket",
    X_NOT_CERTIFIED: "not certified: no neutral mode converged in the bracket, or it failed a certificate",
}


class ThresholdReason(IntEnum):
    """The point-level summary of a threshold search (the first certified crossing): the keys of
    :data:`THRESHOLD_STATUS` (:func:`threshold_chunk`, :func:`critical_gamma_chunk`; atlases' ``gamma_c_reason``)."""

    FOUND = 0
    STABLE = 1
    UNSTABLE = 2
    UNDEFINED = 3
    NOT_CERTIFIED = 4
    JUMP = 5
    POLE_DENSE = 6


T_FOUND, T_STABLE, T_UNSTABLE, T_UNDEFINED, T_NOT_CERTIFIED, T_JUMP, T_POLE_DENSE = ThresholdReason
#: reason codes of :func:`threshold_chunk` / :func:`critical_gamma_chunk` (int8), like :data:`STATUS`
THRESHOLD_STATUS = {
    T_FOUND: "found: the first certified crossing (a neutral mode where the max growth changes sign)",
    T_STABLE: "stable throughout: max growth < 0 at every scan value of the range where it is defined",
    T_UNSTABLE: "unstable throughout: max growth >= 0 at every scan value of the range where it is defined",
    T_UNDEFINED: "undefined: the max growth is NaN (no certified root) at the scan values needed to bracket a "
    "crossing, or inside the bracket",
    T_NOT_CERTIFIED: "not certified: the max growth changes sign, but no neutral mode there passed the certificates",
    T_JUMP: "jump, not a threshold: the max growth jumps across zero (the part of the kH range where the branch is "
    "followed, its route or its pole-dense part changes), with no neutral mode",
    T_POLE_DENSE: "pole-dense: the sign change is at a neutral mode among the lower block's poles (finite eta)",
}
POINT_REASON = {X_JUMP_MASKED: T_JUMP, X_JUMP: T_JUMP, X_POLE_DENSE: T_POLE_DENSE, X_UNDEFINED: T_UNDEFINED,
                 X_NOT_CERTIFIED: T_NOT_CERTIFIED}


@dataclass(frozen=True)
class Crossings:
    """Every crossing of the max growth in a parameter range, per parameter set (:func:`critical_gammas`).

    The last axis (length max_crossings) lists crossings in increasing order of the parameter, NaN-padded.

    Attributes
    ----------
    value : the threshold where certified (reason 0 or 1), else NaN
    location : where the sign change is: the threshold, the jump's location (to NARROW), or the bracket's centre
    lo, hi : the bracket (values of the parameter) the crossing was solved in (the certificate's ends if certified)
    kH, z : the neutral mode's kH and z (real) where certified, else NaN
    direction : +1 destabilising (the max growth goes from < 0 to > 0 as the parameter grows), -1 stabilising,
        0 where not certified or padding
    reason : int8, a key of :data:`CROSSING_STATUS` (-1: padding)
    count : how many sign changes were found (may exceed max_crossings: then only the first are listed)
    complete : every sign change found is certified (a sign change across scan values where the max growth is
        undefined is one that is not)
    defined : the max growth is defined (finite) at every scan value
    status : int8, the first certified crossing's code (0) or why there is none (:data:`THRESHOLD_STATUS`)
    growth_min, growth_max : extremes of the max growth at the scan values (NaN if none defined)
    n_undetermined : scan values where the growth's verdict is undetermined (branch lost or pole-dense there)
    evaluations : growth evaluations per parameter set
    """

    value: np.ndarray
    location: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    kH: np.ndarray
    z: np.ndarray
    direction: np.ndarray
    reason: np.ndarray
    count: np.ndarray
    complete: np.ndarray
    defined: np.ndarray
    status: np.ndarray
    growth_min: np.ndarray
    growth_max: np.ndarray
    n_undetermined: np.ndarray
    evaluations: np.ndarray
    parameter: str = field(default="gamma")

    @property
    def first(self) -> np.ndarray:
        """The first certified crossing (NaN where there is none): what :func:`critical_gamma` returns."""
        ok = (self.reason == X_CERTIFIED) | (self.reason == X_EDGE)
        idx = np.argmax(ok, axis=-1)
        v = np.take_along_axis(self.value, idx[..., None], axis=-1)[..., 0]
        return np.where(ok.any(axis=-1), v, np.nan)


PER_POINT = ("value", "location", "lo", "hi", "kH", "z", "direction", "reason")
