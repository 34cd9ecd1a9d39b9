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
# Status reads while waiting for a command's result back off: the first read follows the
# command at once, then ACK_BACKOFF_FIRST, doubling, capped at ACK_BACKOFF_CAP (short
# commands) or MOVE_POLL_INTERVAL (moves). No spinning on a real controller.
ACK_BACKOFF_FIRST = 0.001
ACK_BACKOFF_CAP = 0.01
# Completion rule "observe" (GV291 not writable): an instant command whose status never moved
# from the 0xFF it had before is "done, unconfirmed" after this long (the controller would have
# shown an error by then). Raised at run time to UNCONFIRMED_LATENCY_FACTOR x the slowest
# acknowledgement seen on the link. Must exceed the controller's command latency.
UNCONFIRMED_AFTER = 0.05
UNCONFIRMED_LATENCY_FACTOR = 2.0
# Auto-detection of a writable GV291: wait this long after writing the sentinel before reading
# it back, so a controller that re-publishes its status every scan has overwritten it by then.
SENTINEL_PROBE_SETTLE = 0.05
ACK_SPIN = 0.05  # s the worker reads GV291 back to back after a command until it changes
ACK_TIMEOUT = 2.0  # s for the controller to show it has taken a command (leave the stale code)
CREATE_POINT_TIMEOUT = 3.0  # s for create-point / teach enable to finish
MOVE_TIMEOUT_MIN = 10.0  # s; a move's timeout is max(this, 3 x its estimated duration)
STOP_SETTLE = 0.3  # s a moved command must read 'stopped' with GV291 = 0 before it counts as stopped
# A command the controller took whose status reads then fail: they are retried every
# OUTCOME_READ_RETRY for at least OUTCOME_READ_BUDGET after the first failure (longer while the
# command's own time runs), then its outcome is "unknown" (app/link/command_client.py follow).
OUTCOME_READ_BUDGET = 2.0
OUTCOME_READ_RETRY = 0.05
# Modbus exception 6 (server device busy) means "try again later". A write that is safe to repeat
# (an upload's point: re-creating the same point at the same pose is idempotent; never a move) is
# tried again after BUSY_BACKOFF_FIRST, doubling up to BUSY_BACKOFF_CAP, for at most
# BUSY_RETRY_BUDGET s from the first busy answer of that point (app/link/busy.py); then it fails
# as refused "busy". The wait is cut in BUSY_BACKOFF_SLICE pieces so a Stop never waits for it.
BUSY_BACKOFF_FIRST = 0.05
BUSY_BACKOFF_CAP = 0.5
BUSY_RETRY_BUDGET = 5.0
BUSY_BACKOFF_SLICE = 0.02
# A noisy serial line (RTU): a frame damaged on the wire (a CRC or length error, a garbled answer,
# no answer to a damaged request) is sent again where that is safe (app/link/line_retry.py): a read
# up to LINE_READ_RETRIES more times; a write of value registers (an upload's pose GVs, GV200-202,
# GV245) read back and, unless it took, written again up to LINE_WRITE_RETRIES times; an upload's
# point (the same point at the same pose: idempotent) sent whole again up to LINE_POINT_RETRIES
# times. Never a motion command. Only on a serial line (on TCP a bad answer is not line noise).
LINE_READ_RETRIES = 4
LINE_WRITE_RETRIES = 3
LINE_POINT_RETRIES = 5
# ... of which at most this many after no answer at all (a damaged request: rare twice in a row;
# a controller that went silent is told about soon, not after every budget ran out); an upload's
# point, LINE_POINT_TIMEOUT_RETRIES.
LINE_TIMEOUT_RETRIES = 1
LINE_POINT_TIMEOUT_RETRIES = 2
# After a bad frame on a serial line the input is dropped until the line has been silent this long
# (s; at least 3.5 characters at the baud rate, twice), at most one request timeout: the rest of a
# damaged answer is never read as the start of the next one.
RTU_RESYNC_QUIET = 0.03

# Worker (GUI side).
POLL_HZ_DEFAULT = 50
CLOCK_POLL_PERIOD = 1.0  # s between date/time and restart-canary reads (another master seen in 1 s)
# s after a write of ours during which a GV291 change may be its answer (app/link/foreign.py)
FOREIGN_RESULT_WINDOW = 2.0
# s after a sign of another master during which no move is sent (app/link/foreign.py)
FOREIGN_MOVE_HOLD = 5.0
# s after a restart the canary reads 0 before our fresh token is written: other TeachPads
# (reading it once a CLOCK_POLL_PERIOD) see the restart too (app/link/supervisor.py)
CANARY_REARM_DELAY = 3.0
RECONNECT_BACKOFF = (0.2, 0.5, 1.0, 2.0, 5.0)  # s, last one repeats
LINK_LOSS_POLLS = 3  # consecutive failed transactions (refused, reset, command timeouts) -> link down
NOT_ANSWERING_DOWN_AFTER = 3.0  # s of silence (polls timing out, link open) before the link is down
RTT_REPORT_PERIOD = 0.5  # s between rttChanged / linkStatsChanged emissions
# s between trafficObserved batches while capturing (the table refreshes ~2x/s): one queued call
# into the GUI thread per period instead of one per poll; a command's result, a connection change,
# capture off and shutdown deliver what is pending at once.
TRAFFIC_DELIVERY_PERIOD = 0.1
# A write that stops motion (a jog's speed 0, a Stop) the controller refused or did not answer is
# sent again at every poll (app/link/halt.py). Not confirmed this long after the release -- or
# answered while the arm kept moving -- a Stop (441) goes out too, at every poll: 0.5 s is
# 12.5 mm at the 10 % jog of the field report (5 to 10 polls), short of a second refusal's worth.
HALT_ESCALATE_AFTER = 0.5
# teachpad-cli keeps trying that long (s) before it gives up, says the arm may still move, exits 1.
HALT_CONFIRM_BUDGET = 10.0
# A Pause the controller refused or did not answer is sent again at every poll (app/link/halt.py);
# not confirmed this long after the press (answered, or the program state reads paused), a Stop
# goes out instead: the operator asked for the arm to halt, and a Pause is only the gentler way.
# Longer than a jog's: a controller busy for a second or so (exception 6) still gets its Pause
# (resumable), yet the arm never runs on for more than this against the operator's request.
PAUSE_ESCALATE_AFTER = 2.0
TEACH_IDLE_DISABLE = 30.0  # s after the last jog release before teach mode is disabled
TEACH_MODE_GRACE = 0.3  # s after teach enable during which a status without mode 2 is not "teach lost"
UPLOAD_CHUNK_POINTS = 20  # points per event-loop turn of an upload, at most ...
UPLOAD_CHUNK_SECONDS = 0.03  # ... or this long (s), whichever comes first
UPLOAD_PROGRESS_PERIOD = 0.05  # s between an upload's UploadProgress reports (the last one always goes out)
UPLOAD_RECORD_PERIOD = 1.0  # s between two writes of teachpad-cli's upload record during an upload
SHUTDOWN_WAIT = 1.5  # s the GUI waits for the worker thread on shutdown before detaching it

# Simulator.
SIM_TICK_HZ = 100
SIM_COMMAND_LATENCY = 0.001  # s from a create/teach command to its final GV291
# Simulator timing profile "slow": the old GV291 stays for SIM_SLOW_PICKUP, then 0 shows for
# SIM_SLOW_ZERO, then the result (each uniform in the range, seeded).
SIM_SLOW_PICKUP = (0.005, 0.025)
SIM_SLOW_ZERO = (0.002, 0.015)

# --- teachpad-gateway, the Sparkplug B edge node (app/gateway; issue 23) --------------------------
GATEWAY_POLL_HZ = 20.0  # polls per controller per s (a silent one: DDEATH by the rule below)
# s: a controller is dead (DDEATH) once it has not answered this long since its last answer, whatever the
# poll timeout (app/gateway/poller.py): within the 250 ms of silence; a busy PC's late answers kept
GATEWAY_DEATH_AFTER = 0.2
GATEWAY_RECONNECT_BACKOFF = (0.2, 0.5, 1.0, 2.0)  # s between polls of a controller that does not answer
GATEWAY_KEEPALIVE = 30  # s, the MQTT keepalive: the broker sends NDEATH at most 1.5 x this after a crash
GATEWAY_BROKER_RETRY = (
    1,
    30,
)  # whole s: paho's reconnect delay to the broker (first, doubling to the largest)
GATEWAY_CLOCK_PERIOD = 1.0  # s between reads of the controller's clock (with the status block)
GATEWAY_STOP_WAIT = 2.0  # s a stopping gateway waits for its NDEATH to be sent
GATEWAY_STOP_BOUND = 10.0  # s teachpad-gateway's whole stop may take after SIGTERM/SIGINT; then it exits
# DDATA kept while the broker is away (sent flagged is_historical when it is back); older ones are dropped
GATEWAY_HISTORY_LIMIT = 10_000
# A plant write (DCMD) is refused while another master was seen on that controller this recently (s):
# a pendant stepping or moving to points between its commands still commands the robot
GATEWAY_PLANT_PENDANT_WINDOW = 10.0
GATEWAY_PLANT_COMMAND_TTL = 2.0  # s a DCMD may wait for its robot's poller; older: refused, never late

# --- measured stopping (app/safety/stopping.py; issue 24) ----------------------------------------
STOP_STILL_TIMEOUT = 5.0  # s after a Stop / jog release within which the arm must be seen still
# s two polls alike must be apart to count as still: polls that come in a bunch (a late poller
# catching up) can read one controller update twice while the arm still moves
STOP_STILL_SPAN = 0.03
