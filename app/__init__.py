"""TeachPad core: protocol, simulator, client and data models (no widgets)."""

__version__ = "0.1.0"
