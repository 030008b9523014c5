"""The grasp monitor's options, checked once when the monitor is made.

:class:`MonitorSettings` holds what a :class:`~drakegrasp.GraspMonitor` needs
besides its plant, object and hand: the analysis options (an
:class:`~drakegrasp.AnalysisOptions`, the object
:func:`~drakegrasp.analyze_grasp` takes), where the contacts come from, when it
samples, whether it computes ε, and the holding thresholds.
:func:`monitor_settings` makes one from a monitor's keywords, refusing at
construction every option that no configuration of the plant could fix, so a
bad value stops there and not in the middle of a simulation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import COUPLING_TOL, MONITOR_COUPLING_TOL
from drakegrasp.core.validation import check_flag, describe, plain_str, real_scalar
from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant.options import AnalysisOptions, resolve_options
from drakegrasp.systems.holding import HoldingThresholds

__all__ = ["CONTACT_SOURCES", "MIN_PERIOD", "MonitorSettings", "monitor_settings"]

CONTACT_SOURCES = ("geometry", "contact_results")
"""Where a monitor's contacts come from: signed distances, or the plant's results."""

MIN_PERIOD = 1e-6
"""Shortest sample period (s) accepted: a plant steps at ~1e-3 s."""


@checked_call
@dataclass(frozen=True)
class MonitorSettings:
    """A grasp monitor's validated options.

    Attributes
    ----------
    analysis : AnalysisOptions
        What each sample's :func:`~drakegrasp.analyze_grasp` is given (``mu`` is
        set: a number or ``"plant"``).  With ``contacts="contact_results"``
        its ``allow_penetration`` is True: the simulator's contacts penetrate
        to make their force, so only joints off their limits make a pose
        invalid.
    contacts : {"geometry", "contact_results"}
        Where the contacts come from.
    period : float
        Seconds between samples (>= :data:`MIN_PERIOD`).
    offset : float
        Time of the first periodic sample, s (>= 0).
    compute_epsilon : bool
        Compute the Ferrari–Canny ε of force-closure samples.
    thresholds : HoldingThresholds
        When a grip is at risk, slips, or has lost contact.
    """

    analysis: AnalysisOptions
    contacts: str
    period: float
    offset: float
    compute_epsilon: bool
    thresholds: HoldingThresholds

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return jsonable(
            {
                "analysis": self.analysis.to_dict(),
                "contacts": self.contacts,
                "period": self.period,
                "offset": self.offset,
                "compute_epsilon": self.compute_epsilon,
                "thresholds": self.thresholds.to_dict(),
            }
        )

    def __str__(self) -> str:
        mu = self.analysis.mu
        return (
            f"MonitorSettings(contacts={self.contacts}, every {self.period:g} s "
            f"from {self.offset:g} s, mu={mu if isinstance(mu, str) else f'{mu:g}'}, "
            f"{self.analysis.contact_model.value}, epsilon "
            f"{'on' if self.compute_epsilon else 'off'})"
        )


def seconds(name: str, value: Any, *, least: float) -> float:
    """``value`` as finite seconds >= ``least``, or an InvalidOptionError."""
    try:  # numpy real scalars as HoldingThresholds takes them; never a bool
        value = real_scalar(name, value)
    except InvalidOptionError:
        raise InvalidOptionError(
            f"{name} must be a real number of seconds, got {describe(value)} "
            f"({type(value).__name__})"
        ) from None
    if not np.isfinite(value) or value < least:
        raise InvalidOptionError(
            f"{name} must be finite and >= {least:g} s, got {describe(value)}"
        )
    return value


def monitor_settings(
    options: AnalysisOptions | None,
    *,
    contacts: str,
    period: Any,
    offset: Any,
    compute_epsilon: Any,
    holding: HoldingThresholds | None,
    **analysis_keywords: Any,
) -> MonitorSettings:
    """A monitor's options, validated once.

    Parameters
    ----------
    options : AnalysisOptions or None
        The analysis options; give them or ``analysis_keywords``, not both
        (:func:`~drakegrasp.plant.options.resolve_options`).
    contacts, period, offset, compute_epsilon, holding
        As in :class:`~drakegrasp.GraspMonitor`.
    **analysis_keywords
        The fields of :class:`~drakegrasp.AnalysisOptions` given one by one.

    Returns
    -------
    MonitorSettings

    Raises
    ------
    InvalidOptionError
        For a missing ``mu`` with ``contacts="geometry"`` (with
        ``"contact_results"`` it is ``"plant"`` when not given) or a soft
        finger's missing ``ν``, any invalid analysis
        option, an unknown contact source, a period or offset that is not
        finite seconds in range, a flag that is not a bool, ``holding``
        that is not a :class:`~drakegrasp.HoldingThresholds`, or its
        ``release_distance`` or ``max_penetration`` at or below
        ``distance_tolerance``.
    """
    contacts = plain_str(contacts)
    if type(contacts) is not str or contacts not in CONTACT_SOURCES:
        raise InvalidOptionError(
            f"contacts must be one of {CONTACT_SOURCES}, got {describe(contacts)}"
        )
    holding = HoldingThresholds() if holding is None else holding
    if not isinstance(holding, HoldingThresholds):
        raise InvalidOptionError(
            f"holding must be a HoldingThresholds, got {type(holding).__name__}"
        )
    # a monitor allows penetration unless told not to: a simulation's
    # contacts penetrate to make their force
    penetrate = options is None and analysis_keywords.get("allow_penetration") is None
    if analysis_keywords.get("allow_penetration") is None:
        analysis_keywords["allow_penetration"] = False  # AnalysisOptions' default
    # and its coupler constraints give under load, as its contacts penetrate
    if analysis_keywords.get("coupling_tolerance") is None:
        analysis_keywords["coupling_tolerance"] = (
            COUPLING_TOL if options is not None else MONITOR_COUPLING_TOL
        )
    analysis = resolve_options(options, **analysis_keywords)
    if penetrate:
        analysis = analysis.replace(allow_penetration=True)
    if contacts == "contact_results" and analysis.mu is None:
        # The simulator's own contacts, with the forces its friction made:
        # their coefficients are the plant's (a number would only be checked
        # against them).
        analysis = analysis.replace(mu="plant")
    analysis = analysis.require_friction()
    if contacts == "contact_results" and not analysis.allow_penetration:
        # The simulator's compliant contact makes its force by penetrating
        # (Drake's point contact: 0.2 mm at 20 N between WSG tips and a box),
        # and these contacts are the simulator's own: a penetration deeper
        # than distance_tolerance is the grip, not an impossible pose.
        analysis = analysis.replace(allow_penetration=True)
    if holding.release_distance <= analysis.distance_tolerance:
        raise InvalidOptionError(
            f"holding.release_distance = {holding.release_distance:g} m must exceed "
            f"distance_tolerance = {analysis.distance_tolerance:g} m: a gap at which "
            "a contact still counts cannot mean the object has left the hand"
        )
    if holding.max_penetration <= analysis.distance_tolerance:
        raise InvalidOptionError(
            f"holding.max_penetration = {holding.max_penetration:g} m must exceed "
            f"distance_tolerance = {analysis.distance_tolerance:g} m: a depth "
            "within the tolerance is a contact, never seen as a penetration"
        )
    return MonitorSettings(
        analysis=analysis,
        contacts=contacts,
        period=seconds("period", period, least=MIN_PERIOD),
        offset=seconds("offset", offset, least=0.0),
        compute_epsilon=check_flag("compute_epsilon", compute_epsilon),
        thresholds=holding,
    )
