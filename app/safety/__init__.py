"""Guard rails, Qt-free; the GUI and the worker call into them.

* :mod:`app.safety.envelope` — joint limits, keep-in / keep-out boxes, speed caps, reduced mode;
  checks of targets, steps, paths, plan segments (:func:`~app.safety.envelope.plan_violations`
  feeds :func:`app.plan.checks.check_plan`).
* :mod:`app.safety.jog_guard` — stop a jog before a boundary, allow jogging back out.
* :mod:`app.safety.profile` — the envelope on disk (JSON, versioned, atomic).
* :mod:`app.safety.roles` — operator / engineer / administrator, scrypt passwords, idle lock.
* :mod:`app.safety.audit` — the append-only JSON-lines audit trail (write-ahead); :mod:`app.safety.audit_read`
  its reader, filters and CSV export.
* :mod:`app.safety.bundle` — the support bundle zip.
* :mod:`app.safety.register_profile` — what varies between controllers (word order, unit, completion
  rule, poll timeout), versioned JSON, changed by the administrator only.
* :mod:`app.safety.session` — one object tying them together for the GUI.
"""
