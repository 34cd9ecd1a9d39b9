"""Robot model profiles shipped with TeachPad (JSON, see :mod:`app.view3d.profile`)."""
