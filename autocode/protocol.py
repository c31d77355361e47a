"""The link's wire format (docs/telemetry.md), written once for the host:
the generator sizes the firmware's buffers from it (schema.link_plan) and
the ground tools frame and decode with it. The firmware's own copy is
firmware/src/fsw_link.h; tests/link/test_protocol_matches_firmware.py holds
the two equal."""

from __future__ import annotations

import struct
from binascii import crc_hqx

PROTOCOL = 2  # the hello frame's protocol number; the firmware's kLinkProtocol
HEADER = 6  # type, sequence number, time (low 32 bits)
CRC = 2  # CRC-16/CCITT-FALSE, high byte first
CRC_INIT = 0xFFFF

# downlink frame types (a sample frame: SAMPLE | stream index)
HELLO, HEALTH, ACK, SNAPSHOT, SAMPLE = 0x01, 0x02, 0x03, 0x04, 0x80
# uplink opcodes
OP_PING, OP_HELLO, OP_SNAPSHOT, OP_SET, OP_MODE = 0x01, 0x02, 0x03, 0x04, 0x05
# parameters (docs/parameters.md)
OP_PARAM_GET, OP_PARAM_SET, OP_PARAM_SAVE, OP_PARAM_BEGIN = 0x06, 0x07, 0x08, 0x09
OP_PARAM_STAGE, OP_PARAM_COMMIT, OP_PARAM_INFO = 0x0A, 0x0B, 0x0C
# the flight recorder (docs/recorder.md)
OP_LOG_INFO, OP_LOG_READ, OP_LOG_ERASE = 0x0D, 0x0E, 0x0F
# machines replaced at run time (docs/reload.md)
OP_MACHINE_INFO, OP_MACHINE_BEGIN, OP_MACHINE_WRITE, OP_MACHINE_COMMIT, OP_MACHINE_ACTIVATE = 0x10, 0x11, 0x12, 0x13, 0x14
OP_NAMES = {OP_PING: "ping", OP_HELLO: "hello", OP_SNAPSHOT: "snapshot", OP_SET: "set", OP_MODE: "mode",
            OP_PARAM_GET: "param_get", OP_PARAM_SET: "param_set", OP_PARAM_SAVE: "param_save",
            OP_PARAM_BEGIN: "param_begin", OP_PARAM_STAGE: "param_stage", OP_PARAM_COMMIT: "param_commit",
            OP_PARAM_INFO: "param_info", OP_LOG_INFO: "log_info", OP_LOG_READ: "log_read",
            OP_LOG_ERASE: "log_erase", OP_MACHINE_INFO: "machine_info", OP_MACHINE_BEGIN: "machine_begin",
            OP_MACHINE_WRITE: "machine_write", OP_MACHINE_COMMIT: "machine_commit",
            OP_MACHINE_ACTIVATE: "machine_activate"}
# acknowledgement status: 0 applied, anything else refused
STATUS = {
    0: ("OK", "applied"),
    1: ("REPLAY", "sequence number not newer than the last accepted command"),
    2: ("UNKNOWN_OP", "unknown opcode"),
    3: ("BAD_LENGTH", "arguments of the wrong length"),
    4: ("NOT_WRITABLE", "the element is not in the application's [uplink] list"),
    5: ("BAD_TASK", "no such task"),
    6: ("BAD_MODE", "mode must be 0 disabled, 1 safed or 2 enabled"),
    7: ("LOCKED", "the executor keeps it: the uplink task's own mode, the mode of the outputs task that ends "
                  "the pyro pulses, a task's mode, overruns or worst_us element, the reset cause (modes change "
                  "only by `mode`)"),
    8: ("NO_PARAM", "no such parameter"),
    9: ("OUT_OF_RANGE", "a value outside the parameter's range"),
    10: ("WRONG_STATE", "the declaring machine is not in a state that allows a change"),
    11: ("BUSY", "a parameter bank is being written, or the stage queue is full: try again"),
    12: ("NO_LOAD", "no parameter load is open (PARAM_BEGIN first)"),
    13: ("MISMATCH", "the staged set's CRC is not the one committed"),
    14: ("TOO_BIG", "the image and its state mask do not fit a slot ([reload] size)"),
    15: ("BAD_IMAGE", "the board's verifier refused the image"),
    16: ("NO_IMAGE", "that slot holds no committed image"),
}

# payloads, little-endian
# protocol, schema, time_hi, frames, version x3, reset cause, last_seq, parameter store state
HELLO_PAYLOAD = struct.Struct("<BIIIBBBBHB")
# time_hi, frames, dropped, cycles, late, reset cause, rx counters, last_seq, parameter store state;
HEALTH_PAYLOAD = struct.Struct("<IIIIHBHHHHHHHB")
# then one HEALTH_TASK per task
HEALTH_TASK = struct.Struct("<BBHH")    # mode, faults, overruns, worst_us
# then one status byte per [pyro] channel (fsw_io.h kPyro*), in [pyro] order
HEALTH_PYRO = 1
PYRO_ARMED, PYRO_CONTINUITY, PYRO_NO_SENSE, PYRO_FIRED, PYRO_FIRING = 0x01, 0x02, 0x04, 0x08, 0x10
# then one health code per sensor part (fsw_sensor.h kSensor*), in `.sns` table order
HEALTH_SENSOR = 1
SENSOR_INIT, SENSOR_OK, SENSOR_NO_ANSWER, SENSOR_BAD_ID, SENSOR_BAD_CALIB, SENSOR_STUCK = 0, 1, 2, 3, 4, 5
SENSOR_HEALTH = {SENSOR_INIT: "init", SENSOR_OK: "ok", SENSOR_NO_ANSWER: "NO ANSWER", SENSOR_BAD_ID: "BAD ID",
                 SENSOR_BAD_CALIB: "BAD CALIBRATION", SENSOR_STUCK: "STUCK"}  # a fault: SENSOR_NO_ANSWER and above
# the reset cause's bit that says the flight's state was resumed (fsw_resume.h)
RESET_RESUMED = 0x80
ACK_PAYLOAD = struct.Struct("<HBBH")    # command seq, opcode, status, last_seq; then a parameter command's data
PARAM_INFO = struct.Struct("<BHHBI")    # source, seq, live CRC, count, table hash
# the parameter store's state byte: bits 0..1 the source, bit 6 unsaved changes, bit 7 a bank being written
PARAM_SOURCES = {0: "no parameters", 1: "defaults", 2: "bank A", 3: "bank B"}
PARAM_DIRTY, PARAM_WRITING = 0x40, 0x80
# MACHINE_INFO's data (docs/reload.md): active, pending, refused slot, its reason, writer busy, slot size,
# image RAM, the open upload (slot, image bytes, mask bytes, CRC, bytes written), then RELOAD_SLOT twice
RELOAD_INFO = struct.Struct("<BBBBBHHBHBHH")
RELOAD_SLOT = struct.Struct("<BHHBH")   # status, seq, image bytes, mask bytes, CRC
RELOAD_INFO_SIZE = RELOAD_INFO.size + 2 * RELOAD_SLOT.size
RELOAD_CRC_FAILS = 0x80  # a refusal's reason beyond the verifier's: the slot's bytes lost their CRC
SNAPSHOT_OFFSET = 2  # a snapshot frame's payload: offset (u16), then state vector bytes


def crc16(data: bytes, crc: int = CRC_INIT) -> int:
    """CRC-16/CCITT-FALSE of `data`, continuing `crc`: the link's frames and
    the parameter banks (the firmware's fsw_crc.h)."""
    return crc_hqx(data, crc)


def encoded_max(n: int) -> int:
    """Wire bytes of a frame of `n` bytes (body + CRC) at most: COBS + delimiter."""
    return n + n // 254 + 2
