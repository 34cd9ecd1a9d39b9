"""How a point's provenance reads in the points table's tooltip (and the compare dialog).

:class:`ProvenanceStamps` makes the provenance of the points the GUI makes (typed, taught,
edited) with the controller the link reaches (its endpoint and unit id, or none) and the
software; :func:`provenance_tip` words a :class:`~app.points.provenance.Provenance` for the
operator, in the window's language.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QCoreApplication

from app.link.types import ControllerIdentity
from app.points.point import TR_CONTEXT as POINTS_CORE_CONTEXT
from app.points.provenance import Origin, Provenance, edited, software_name, stamp

__all__ = ["ProvenanceStamps", "controller_text", "provenance_tip", "when_text"]


def when_text(iso: str) -> str:
    """``2026-11-29T12:00:00Z`` as ``2026-11-29 12:00:00 UTC`` (other text as it is)."""
    if iso.endswith("Z") and "T" in iso:
        return iso[:-1].replace("T", " ") + " UTC"
    return iso


def provenance_tip(made: Provenance) -> str:
    """A few lines: how the point was made, when, on which controller, with which software, the
    file it came from and its last edit."""
    if made.origin is Origin.UNKNOWN and not made.time:
        return QCoreApplication.translate(
            "PointProvenance", "Made: unknown (saved before TeachPad recorded how points are made)"
        )
    how = QCoreApplication.translate(POINTS_CORE_CONTEXT, made.origin.text)
    lines = [QCoreApplication.translate("PointProvenance", "Made: {how}").format(how=how)]
    if made.file:
        lines.append(QCoreApplication.translate("PointProvenance", "File: {file}").format(file=made.file))
    if made.time:
        lines.append(
            QCoreApplication.translate("PointProvenance", "When: {when}").format(when=when_text(made.time))
        )
    lines.append(
        QCoreApplication.translate("PointProvenance", "Controller: {controller}").format(
            controller=made.controller or QCoreApplication.translate("PointProvenance", "none")
        )
    )
    if made.software:
        lines.append(
            QCoreApplication.translate("PointProvenance", "Software: {software}").format(
                software=made.software
            )
        )
    if made.edited:
        where = made.edited_controller or QCoreApplication.translate("PointProvenance", "no controller")
        lines.append(
            QCoreApplication.translate("PointProvenance", "Last edited: {when} ({controller})").format(
                when=when_text(made.edited), controller=where
            )
        )
    return "\n".join(lines)


def controller_text(identity: ControllerIdentity | None) -> str:
    """The controller a point is made on, as kept in the project: ``192.168.1.10:502 unit 1``
    ("" when the link reaches none). The protocol has no serial number to read: the endpoint and
    the unit id are what the link knows (:class:`~app.link.types.ControllerIdentity`)."""
    return "" if identity is None else f"{identity.endpoint} unit {identity.unit}"


class ProvenanceStamps:
    """Stamps for the points the GUI makes. ``controller``: the text of the controller the link
    reaches now ("" when none), asked at each stamp."""

    def __init__(self, controller: Callable[[], str] | None = None) -> None:
        self.controller: Callable[[], str] = controller or (lambda: "")
        self._software: str | None = None

    @property
    def software(self) -> str:
        if self._software is None:  # importlib.metadata: looked up at the first point made
            self._software = software_name()
        return self._software

    def made(self, origin: Origin) -> Provenance:
        return stamp(origin, controller=self.controller(), software=self.software)

    def edited(self, made: Provenance) -> Provenance:
        return edited(made, controller=self.controller())
