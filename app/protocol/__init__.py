"""The Bochuang controller's Modbus contract as code (see shared/PROTOCOL.md)."""
