"""Small reusable widgets (pickers, editors) shared by the panels."""
