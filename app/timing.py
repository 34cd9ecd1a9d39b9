"""Named timing constants, in one place. Tests and settings may override them."""

from __future__ import annotations

# Modbus request timeout (s) and retries of the pymodbus client.
REQUEST_TIMEOUT = 1.0
REQUEST_RETRIES = 0
# Monitoring reads have their own, short timeout so a silent controller is seen at once
# (polling at >= 20 Hz: next poll within 50 ms + this = "not answering" within 250 ms).
POLL_TIMEOUT_TCP = 0.15
POLL_TIMEOUT_RTU_MARGIN = 0.1  # s added to twice the largest answer's time on the wire

# Waiting for a command's GV291 result.
STATUS_POLL_INTERVAL = 0.002  # s between status reads while waiting for a short command
MOVE_POLL_INTERVAL = 0.01  # s between status reads while waiting for a motion
ACK_POLL_INTERVAL = 0.0005  # s between status reads until GV291 leaves the pre-command code
# Short commands (create point, teach) are read back to back (no sleep) for this long.
SHORT_COMMAND_SPIN = 0.005
ACK_SPIN = 0.05  # s the worker reads GV291 back to back after a command until it changes
ACK_TIMEOUT = 2.0  # s for the controller to show it has taken a command (leave the stale code)
CREATE_POINT_TIMEOUT = 3.0  # s for create-point / teach enable to finish
MOVE_TIMEOUT_MIN = 10.0  # s; a move's timeout is max(this, 3 x its estimated duration)
STOP_SETTLE = 0.3  # s a moved command must read 'stopped' with GV291 = 0 before it counts as stopped

# Worker (GUI side).
POLL_HZ_DEFAULT = 50
CLOCK_POLL_PERIOD = 1.0  # s between date/time reads
RECONNECT_BACKOFF = (0.2, 0.5, 1.0, 2.0, 5.0)  # s, last one repeats
LINK_LOSS_POLLS = 3  # consecutive failed transactions (refused, reset, command timeouts) -> link down
NOT_ANSWERING_DOWN_AFTER = 3.0  # s of silence (polls timing out, link open) before the link is down
RTT_REPORT_PERIOD = 0.5  # s between rttChanged / linkStatsChanged emissions
TEACH_IDLE_DISABLE = 30.0  # s after the last jog release before teach mode is disabled
TEACH_MODE_GRACE = 0.3  # s after teach enable during which a status without mode 2 is not "teach lost"
UPLOAD_CHUNK_POINTS = 20  # points per event-loop turn of an upload, at most ...
UPLOAD_CHUNK_SECONDS = 0.03  # ... or this long (s), whichever comes first
UPLOAD_PROGRESS_PERIOD = 0.05  # s between uploadProgress emissions (the last one always goes out)
SHUTDOWN_WAIT = 1.5  # s the GUI waits for the worker thread on shutdown before detaching it

# Simulator.
SIM_TICK_HZ = 100
SIM_COMMAND_LATENCY = 0.001  # s from a create/teach command to its final GV291
