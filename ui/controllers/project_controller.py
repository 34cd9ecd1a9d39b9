"""The open project on the Qt side: file actions, undo stack, dirty state, autosave, recovery.

:class:`ProjectController` owns the :class:`~app.points.project.Project`, the ``QUndoStack`` shared by
every edit, and the table models built on them (:class:`~ui.models.points_model.PointsModel`,
:class:`~ui.models.plan_model.PlanListModel`). Opening, recovering or starting a new project swaps the
project inside the same models (``modelReset``) and clears the undo stack, so the panels keep
their models for the life of the window.

Files: open / save / save as (atomic, by the core), import / export CSV. A malformed file is
refused with the core's message, which names the row (or item) and the field, and nothing
changes. All questions and file choosers go through a :class:`ProjectDialogs` object, replaced
by a fake in tests.

Autosave: every :data:`AUTOSAVE_INTERVAL_S` seconds while the project has unsaved changes, to
``<name>.autosave.json`` next to the project (or the per-user directory for an untitled
project). Off the GUI thread: the GUI thread takes an immutable snapshot (milliseconds) and the
:class:`~app.points.autosave.AutosaveWriter`'s thread turns it into the file and writes it, newest
last; ``autosaved`` (or "Autosave failed: ..." on ``statusMessage``) follows in the GUI thread. A
save removes it (after the write under way, if any, has landed). At startup
:meth:`ProjectController.check_recovery` returns an autosave newer than its project (a crash left
it); :meth:`ProjectController.offer_recovery` asks and loads it. :meth:`ProjectController.close`
stops the timer and waits (at most :data:`AUTOSAVE_FLUSH_S`) for the autosave under way.

One instance per project: the open project's lock file (:mod:`app.points.lock`) is taken when
it is opened or saved under a new name and released when another project replaces it or the
window closes. A project open in another running TeachPad is not opened here, and its live
autosave is never offered for recovery: the operator is told where it is open instead.

A loaded project's points are all *unknown* (a file cannot know what a controller holds).
A CSV without points does not replace all points unless the operator confirms it.
"""

from __future__ import annotations

import copy
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QObject, QTimer, Signal, Slot
from PySide6.QtGui import QAction, QKeySequence, QUndoStack

from app.errors import InvalidInput
from app.points.autosave import AutosaveDone, AutosaveWriter, autosave_path, discard_autosave, find_autosave
from app.points.ledger import PointLedger
from app.points.ledger_import import EmptyImport, ImportMode
from app.points.point import FileFormatError
from app.points.project import PROJECT_SUFFIX, load_project, read_points_csv, save_project, write_points_csv
from app.points.project_model import Project
from app.points.project_write import ProjectTooLarge, project_bytes, take_snapshot
from ui.controllers.project_dialogs import ProjectDialogs
from ui.messages import os_error_text, refusal_text
from ui.models.plan_model import PlanListModel
from ui.models.points_model import PointsModel

if TYPE_CHECKING:  # app.points.lock is imported by the first open / save
    from app.points.lock import LockOwner, ProjectLock

AUTOSAVE_INTERVAL_S = 60.0  # seconds between autosaves while there are unsaved changes
#: The longest a close, a save or a discard waits for the autosave being written (s): a 58 MB
#: project is written in about a second; a stuck disk must not hold the window for ever.
AUTOSAVE_FLUSH_S = 10.0
SAVE_CHOICES = ("save", "discard", "cancel")

__all__ = ["AUTOSAVE_FLUSH_S", "AUTOSAVE_INTERVAL_S", "SAVE_CHOICES", "ProjectController"]


class ProjectController(QObject):
    """See the module docstring.

    Signals: ``projectReplaced(object)`` (the new :class:`Project`), ``dirtyChanged(bool)``,
    ``pathChanged(str)`` ("" when untitled), ``titleChanged(str)`` (name plus "*" when dirty),
    ``autosaved(str)`` (path), ``statusMessage(str)``.

    QActions: ``action_new``, ``action_open``, ``action_save``, ``action_save_as``,
    ``action_import_csv``, ``action_export_csv``, ``action_undo``, ``action_redo``;
    :meth:`file_actions` lists the File menu (None = separator).
    """

    projectReplaced = Signal(object)
    dirtyChanged = Signal(bool)
    pathChanged = Signal(str)
    titleChanged = Signal(str)
    autosaved = Signal(str)
    statusMessage = Signal(str)
    _autosaveDone = Signal(object)  # AutosaveDone, from the writer's thread (queued to the GUI thread)

    def __init__(
        self,
        project: Project | None = None,
        path: str | os.PathLike[str] | None = None,
        *,
        dialogs: Any = None,
        autosave_interval: float = AUTOSAVE_INTERVAL_S,
        autosave_dir: str | os.PathLike[str] | None = None,
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self._project = project or Project()
        self._path: Path | None = Path(path) if path is not None else None
        self.dialogs = dialogs or ProjectDialogs()
        self._autosave_dir = Path(autosave_dir) if autosave_dir is not None else None
        self._saved_revision = self._project.revision
        self._autosaved_revision = self._project.revision
        self._dirty = False
        self._lock: ProjectLock | None = None
        self._foreign_lock: LockOwner | None = None  # another TeachPad has self._path open
        if self._path is not None:
            self._take_lock(self._path)

        self.undo_stack = QUndoStack(self)
        self.points_model = PointsModel(self._project, self.undo_stack, self)
        self.plans_model = PlanListModel(self._project, self.undo_stack, self)
        self.undo_stack.indexChanged.connect(self._check_dirty)
        self.points_model.syncChanged.connect(self._check_dirty)

        self._closed = False
        self._autosaveDone.connect(self._on_autosave_done)
        self.autosaver = AutosaveWriter(self._autosaveDone.emit)
        self._timer = QTimer(self)
        self._timer.timeout.connect(self.autosave_now)
        self.set_autosave_interval(autosave_interval)

        self._make_actions()
        self.retranslate()

    # --- actions
    def _make_actions(self) -> None:
        def act(slot: Any, shortcut: QKeySequence.StandardKey | None = None) -> QAction:
            action = QAction(self)
            if shortcut is not None:
                action.setShortcut(QKeySequence(shortcut))
            action.triggered.connect(lambda _checked=False: slot())
            return action

        self.action_new = act(self.new_project, QKeySequence.StandardKey.New)
        self.action_open = act(self.open_file, QKeySequence.StandardKey.Open)
        self.action_save = act(self.save, QKeySequence.StandardKey.Save)
        self.action_save_as = act(self.save_as, QKeySequence.StandardKey.SaveAs)
        self.action_import_csv = act(self.import_csv)
        self.action_export_csv = act(self.export_csv)
        # the stack keeps their text up to date: "Undo Edit P5 X"
        self.action_undo = self.undo_stack.createUndoAction(self, self.tr("Undo"))
        self.action_undo.setShortcut(QKeySequence(QKeySequence.StandardKey.Undo))
        self.action_redo = self.undo_stack.createRedoAction(self, self.tr("Redo"))
        self.action_redo.setShortcut(QKeySequence(QKeySequence.StandardKey.Redo))

    def retranslate(self) -> None:
        self.action_new.setText(self.tr("&New project"))
        self.action_open.setText(self.tr("&Open project…"))
        self.action_save.setText(self.tr("&Save project"))
        self.action_save_as.setText(self.tr("Save project &as…"))
        self.action_import_csv.setText(self.tr("&Import points (CSV)…"))
        self.action_export_csv.setText(self.tr("&Export points (CSV)…"))
        self.points_model.retranslate()
        self.plans_model.retranslate()

    def file_actions(self) -> list[QAction | None]:
        return [
            self.action_new,
            self.action_open,
            self.action_save,
            self.action_save_as,
            None,
            self.action_import_csv,
            self.action_export_csv,
        ]

    # --- state
    @property
    def project(self) -> Project:
        return self._project

    @property
    def path(self) -> Path | None:
        return self._path

    @property
    def is_dirty(self) -> bool:
        return self._project.revision != self._saved_revision

    @property
    def display_name(self) -> str:
        return self._path.name if self._path is not None else self.tr("untitled")

    @property
    def title(self) -> str:
        return self.display_name + ("*" if self.is_dirty else "")

    @property
    def autosave_timer(self) -> QTimer:
        return self._timer

    @property
    def autosave_file(self) -> Path:
        return autosave_path(self._path, user_dir=self._autosave_dir)

    def set_autosave_interval(self, seconds: float) -> None:
        """0 turns autosave off."""
        self._timer.stop()
        if seconds > 0:
            self._timer.setInterval(int(seconds * 1000))
            self._timer.start()

    # --- file operations
    @Slot()
    def new_project(self) -> bool:
        if not self.maybe_save():
            return False
        self._replace(Project(), None)
        return True

    def open_file(self, path: str | os.PathLike[str] | None = None) -> bool:
        """Open a project (asks for the file when ``path`` is None). A bad file is refused
        with the core's message and the open project stays as it was."""
        from app.points.lock import live_owner  # not before the first paint

        if path is None:
            chosen = self.dialogs.open_path(self.tr("Open project"), self._project_filter())
            if not chosen:
                return False
            path = chosen
        if not self.maybe_save():
            return False
        owner = live_owner(path)
        if owner is not None:
            self.dialogs.error(self.tr("Project in use"), self._in_use_text(Path(path), owner))
            return False
        try:
            project = load_project(path, self._project.ledger.limits)
        except (FileFormatError, InvalidInput) as exc:
            self.dialogs.error(self.tr("Cannot open project"), refusal_text(exc))
            return False
        except OSError as exc:
            self.dialogs.error(self.tr("Cannot open project"), os_error_text(path, exc))
            return False
        self._replace(project, Path(path))
        self.statusMessage.emit(self.tr("Opened {path}").format(path=path))
        return True

    @Slot()
    def save(self) -> bool:
        if self._path is None:
            return self.save_as()
        return self._save_to(self._path)

    def save_as(self, path: str | os.PathLike[str] | None = None) -> bool:
        if path is None:
            suggested = str(self._path) if self._path else self._project.name + PROJECT_SUFFIX
            chosen = self.dialogs.save_path(self.tr("Save project"), self._project_filter(), suggested)
            if not chosen:
                return False
            path = chosen
        target = Path(path)
        if not target.name.endswith(".json"):
            target = target.with_name(target.name + PROJECT_SUFFIX)
        return self._save_to(target)

    def _save_to(self, target: Path) -> bool:
        from app.points.lock import live_owner  # not before the first paint

        old_autosave = self.autosave_file
        owner = live_owner(target)
        if owner is not None:
            self.dialogs.error(self.tr("Project in use"), self._in_use_text(target, owner))
            return False
        self._drain_autosave()  # none lands after the save has removed it
        try:
            save_project(self._project, target)
        except ProjectTooLarge as exc:
            self.dialogs.error(self.tr("Cannot save project"), refusal_text(exc))
            return False
        except OSError as exc:
            self.dialogs.error(self.tr("Cannot save project"), os_error_text(target, exc))
            return False
        old_path, self._path = self._path, target
        if old_path != target or self._lock is None:
            self._take_lock(target)
        self._saved_revision = self._autosaved_revision = self._project.revision
        self.undo_stack.setClean()
        for stale in {old_autosave, self.autosave_file}:
            stale.unlink(missing_ok=True)
        if old_path != target:
            self.pathChanged.emit(str(target))
        self._check_dirty(force=True)
        self.statusMessage.emit(self.tr("Saved {path}").format(path=target))
        return True

    def import_csv(self, path: str | os.PathLike[str] | None = None, mode: ImportMode | None = None) -> bool:
        """Import points from CSV (one undo step). A bad file leaves the table as it was."""
        if path is None:
            chosen = self.dialogs.open_path(self.tr("Import points"), self._csv_filter())
            if not chosen:
                return False
            path = chosen
        try:
            points = read_points_csv(path, self._project.ledger.limits)
        except (FileFormatError, InvalidInput) as exc:
            self.dialogs.error(self.tr("Cannot import points"), refusal_text(exc))
            return False
        except OSError as exc:
            self.dialogs.error(self.tr("Cannot import points"), os_error_text(path, exc))
            return False
        if mode is None:
            mode = self.dialogs.ask_import_mode()
            if mode is None:
                return False
        check = self._fits_when_saved
        try:
            try:
                report = self.points_model.import_points(points, mode, check=check)
            except EmptyImport as exc:
                if not self.dialogs.ask_empty_import(exc.existing):
                    return False
                report = self.points_model.import_points(points, mode, allow_empty=True, check=check)
        except InvalidInput as exc:
            self.dialogs.error(self.tr("Cannot import points"), refusal_text(exc))
            return False
        counts = self.tr("{added} added, {updated} updated, {unchanged} unchanged, {removed} removed").format(
            added=report.added, updated=report.updated, unchanged=report.unchanged, removed=report.removed
        )
        self.statusMessage.emit(self.tr("Imported {path}: {report}").format(path=path, report=counts))
        return True

    def _fits_when_saved(self, ledger: PointLedger) -> None:
        """:class:`ProjectTooLarge` when the project holding ``ledger`` could not be saved and
        opened again (an import is refused first: never a file TeachPad then refuses to open)."""
        project = copy.copy(self._project)
        project.ledger = ledger
        project_bytes(project)

    def export_csv(self, path: str | os.PathLike[str] | None = None) -> bool:
        if path is None:
            suggested = (self._path.name.removesuffix(PROJECT_SUFFIX) if self._path else "points") + ".csv"
            chosen = self.dialogs.save_path(self.tr("Export points"), self._csv_filter(), suggested)
            if not chosen:
                return False
            path = chosen
        try:
            write_points_csv(path, self._project.ledger)
        except OSError as exc:
            self.dialogs.error(self.tr("Cannot export points"), os_error_text(path, exc))
            return False
        self.statusMessage.emit(
            self.tr("Exported {n} points to {path}").format(n=len(self._project.ledger), path=path)
        )
        return True

    def maybe_save(self) -> bool:
        """Ask to save unsaved changes; False when the operator cancels."""
        if not self.is_dirty:
            return True
        choice = self.dialogs.ask_save_changes(self.display_name)
        if choice == "save":
            return self.save()
        if choice == "discard":
            self._drain_autosave()
            discard_autosave(self._path, user_dir=self._autosave_dir)
            return True
        return False

    # --- autosave and recovery
    @Slot()
    def autosave_now(self) -> Path | None:
        """Autosave if there are changes since the last save / autosave: the snapshot is taken
        here, the file written by the writer's thread (``autosaved`` when it is on disk). Returns
        the autosave's path, or None when there was nothing to save."""
        revision = self._project.revision
        if self._closed or not self.is_dirty or revision == self._autosaved_revision:
            return None
        target = self.autosave_file
        self.autosaver.submit(take_snapshot(self._project), target)
        self._autosaved_revision = revision
        return target

    def wait_autosave(self, timeout: float = AUTOSAVE_FLUSH_S) -> bool:
        """Wait until the autosave submitted last is written (or failed); False after ``timeout``."""
        return self.autosaver.flush(timeout)

    @Slot(object)
    def _on_autosave_done(self, done: AutosaveDone) -> None:
        if done.error is None:
            self.autosaved.emit(str(done.target))
            return
        if done.revision == self._autosaved_revision:
            self._autosaved_revision = -1  # not on disk: the next tick tries again
        if isinstance(done.error, ProjectTooLarge):
            reason = refusal_text(done.error)
        elif isinstance(done.error, OSError):
            reason = os_error_text(done.target, done.error)
        else:
            reason = str(done.error) or type(done.error).__name__
        self.statusMessage.emit(self.tr("Autosave failed: {reason}").format(reason=reason))

    def _drain_autosave(self) -> None:
        """Before a save, a discard or another project: the autosave waiting is dropped and the
        one being written lands (bounded), so none appears after it was removed."""
        self.autosaver.cancel()
        if not self.autosaver.flush(AUTOSAVE_FLUSH_S):
            self.statusMessage.emit(
                self.tr("The autosave {path} is still being written after {seconds} s.").format(
                    path=self.autosave_file, seconds=f"{AUTOSAVE_FLUSH_S:g}"
                )
            )

    def check_recovery(self) -> Path | None:
        """The autosave to offer at startup (newer than the project, or of an untitled one);
        None when another running TeachPad has the project open (its autosave is live)."""
        if self.lock_owner is not None:
            return None
        return find_autosave(self._path, user_dir=self._autosave_dir)

    def offer_recovery(self) -> bool:
        """Ask whether to recover :meth:`check_recovery`'s file; True when recovered.
        Declining removes the autosave. When another TeachPad has the project open, says so
        instead (its autosave is that TeachPad's work in progress, not a crash leftover)."""
        owner = self.lock_owner
        if owner is not None and self._path is not None:
            self.dialogs.error(self.tr("Project in use"), self._in_use_text(self._path, owner))
            return False
        found = self.check_recovery()
        if found is None:
            return False
        if not self.dialogs.ask_recover(found, self._path):
            found.unlink(missing_ok=True)
            return False
        return self.recover(found)

    def recover(self, autosave: str | os.PathLike[str]) -> bool:
        """Load an autosave in place of the project; it stays unsaved (the autosave is kept
        until the next save)."""
        try:
            project = load_project(autosave, self._project.ledger.limits)
        except (FileFormatError, InvalidInput) as exc:
            self.dialogs.error(self.tr("Cannot recover autosave"), refusal_text(exc))
            return False
        except OSError as exc:
            self.dialogs.error(self.tr("Cannot recover autosave"), os_error_text(autosave, exc))
            return False
        self._replace(project, self._path, dirty=True)
        self.statusMessage.emit(self.tr("Recovered the autosave {path}").format(path=autosave))
        return True

    @Slot()
    def close(self) -> bool:
        """Stop autosaving, let the autosave under way land (at most :data:`AUTOSAVE_FLUSH_S`) and
        release the project's lock (the window is closing; call :meth:`maybe_save` first). False
        when the autosave was still being written (then said on ``statusMessage``)."""
        self._timer.stop()
        self._closed = True
        landed = self.autosaver.flush(AUTOSAVE_FLUSH_S)
        if not landed:
            self.statusMessage.emit(
                self.tr("The autosave {path} is still being written after {seconds} s.").format(
                    path=self.autosave_file, seconds=f"{AUTOSAVE_FLUSH_S:g}"
                )
            )
        self.autosaver.close(0.0 if not landed else AUTOSAVE_FLUSH_S)
        self._release_lock()
        return landed

    @property
    def lock_owner(self) -> LockOwner | None:
        """Another running TeachPad that has this project open (None: the project is ours,
        or untitled). When that TeachPad has gone, this one takes the lock."""
        from app.points.lock import live_owner  # not before the first paint

        if self._path is None or (self._lock is not None and self._lock.held):
            return None
        owner = live_owner(self._path)
        if owner is None:
            self._take_lock(self._path)
            return self._foreign_lock
        return owner

    # --- the one-instance lock
    def _take_lock(self, path: Path) -> None:
        from app.points.lock import ProjectLock, ProjectLocked  # not before the first paint

        self._release_lock()
        self._foreign_lock = None
        try:
            self._lock = ProjectLock.acquire(path)
        except ProjectLocked as exc:
            self._foreign_lock = exc.owner
        except OSError as exc:  # e.g. a read-only directory: work without a lock, and say so
            self.statusMessage.emit(
                self.tr("Cannot lock {path}: {reason}").format(path=path, reason=os_error_text(path, exc))
            )

    def _release_lock(self) -> None:
        if self._lock is not None:
            self._lock.release()
            self._lock = None

    def _in_use_text(self, path: Path, owner: LockOwner) -> str:
        return self.tr(
            "{path} is open in another TeachPad (process {pid} on {host}, since {started}). "
            "Close it there first; its autosave belongs to that TeachPad and is not offered "
            "for recovery here."
        ).format(path=path, pid=owner.pid, host=owner.host or "?", started=owner.started or "?")

    # --- internals
    def _replace(self, project: Project, path: Path | None, *, dirty: bool = False) -> None:
        self._drain_autosave()  # the old project's autosave lands before anything changes
        old_path = self._path
        self.undo_stack.clear()
        self._project = project
        self._path = path
        if path != old_path:
            if path is None:
                self._release_lock()
                self._foreign_lock = None
            else:
                self._take_lock(path)
        self._saved_revision = project.revision - (1 if dirty else 0)
        self._autosaved_revision = project.revision
        self.points_model.set_project(project)
        self.plans_model.set_project(project)
        self.projectReplaced.emit(project)
        if old_path != path:
            self.pathChanged.emit(str(path) if path else "")
        self._check_dirty(force=True)

    def note_changed(self) -> None:
        """The project changed outside the undo stack (its watch list): the title and the dirty
        state follow."""
        self._check_dirty()

    def _check_dirty(self, *_args: Any, force: bool = False) -> None:
        dirty = self.is_dirty
        if dirty != self._dirty or force:
            changed = dirty != self._dirty
            self._dirty = dirty
            if changed:
                self.dirtyChanged.emit(dirty)
            self.titleChanged.emit(self.title)

    def _project_filter(self) -> str:
        return self.tr("TeachPad projects (*.teachpad.json *.json);;All files (*)")

    def _csv_filter(self) -> str:
        return self.tr("CSV files (*.csv);;All files (*)")
