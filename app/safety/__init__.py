"""Guard rails: the safety envelope, the jog guard, operator roles, the audit trail and the
support bundle. Qt-free; the GUI and the worker call into it."""
