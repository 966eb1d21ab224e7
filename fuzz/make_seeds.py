#!/usr/bin/env python3
"""Writes the hand-made seed inputs of the fuzz targets into fuzz/corpus/<target>/.

The committed corpora are these seeds plus what `cargo fuzz cmin` kept of the
fuzzing runs; re-running this script only (re)writes the `seed-*` files.
Byte layouts follow fuzz/src/guard.rs and fuzz/src/link.rs.
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def put(target, name, data):
    d = os.path.join(HERE, "corpus", target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, "seed-" + name), "wb") as f:
        f.write(data)


# ------------------------------------------------------------------ guard

def ramp(n, slopes):
    """Ramp op: selector 0, n ticks (1..=64), six signed slope bytes."""
    return bytes([0, (n - 1) % 64]) + bytes(s & 0xFF for s in slopes)


HOLD = [0, 0, 0, 0, 0, 0]
UP = [40, 40, -10, 40, 20, 5]
DOWN = [-40, -30, 10, -40, -20, -5]
START = bytes([150, 140, 10, 130, 128, 70])  # channel start fractions
COLD = bytes([0])


def valid_run(k):
    out = b""
    for i in range(k):
        out += ramp(64, UP if i % 3 == 0 else DOWN if i % 3 == 1 else HOLD)
    return out


def warm(base, used=0):
    # variant 8: restore kind 2 (sealed record near the thresholds)
    b = bytes([8, base]) + bytes([0, 10, 256 - 10, 5, 0, 3]) + bytes([140])
    return b + struct.pack("<IHB", used, 0, 0)


def guard_seeds():
    s = {}
    s["cold-valid"] = COLD + START + valid_run(20)
    s["warm-40c"] = warm(100) + START + valid_run(20)  # 15 + 0.25*100 = 40 degC
    s["warm-60c"] = warm(180) + START + valid_run(20)  # 60 degC
    s["warm-lng-low"] = warm(104, 0xFFFF0000) + START + valid_run(10)
    s["missing-stale"] = COLD + START + valid_run(2) + bytes([195, 7]) + valid_run(4)
    s["missing-short"] = COLD + START + valid_run(2) + bytes([195, 2]) + valid_run(4)
    for ch in range(6):
        s[f"nan-ch{ch}"] = COLD + START + valid_run(2) + bytes([205, ch, ch % 3]) + valid_run(4)
        s[f"range-ch{ch}"] = COLD + START + valid_run(2) + bytes([211, ch, 30, ch & 1]) + valid_run(4)
        s[f"rate-ch{ch}"] = COLD + START + valid_run(2) + bytes([217, ch, 128]) + valid_run(4)
    s["clear-early"] = COLD + START + valid_run(1) + bytes([205, 0, 0, 225]) + valid_run(1) + bytes([225])
    s["refill"] = warm(100, 0x00FFFFFF) + START + valid_run(2) + bytes([233]) + valid_run(2)
    s["actuator"] = COLD + START + valid_run(1) + bytes([238]) + valid_run(4)
    s["reboot"] = warm(120) + START + valid_run(3) + bytes([241]) + valid_run(3)
    raw = struct.pack("<6f", float("nan"), 1e30, -1e30, 3.0e38, -0.0, 1e-40)
    s["raw-sample"] = COLD + START + valid_run(1) + bytes([250]) + raw + valid_run(3)
    # variant 3: fuzzed knobs (stale 3, clear 20, dwell 40, valve 30/29, alarm 35/34, 0.02 L LNG)
    knobs = bytes([3, 2, 10, 10, 40, 50, 60, 50, 10, 128])
    s["knobs-small-lng"] = knobs + START + valid_run(12)
    s["record-sealed-zero"] = bytes([12]) + bytes(40) + START + valid_run(6)
    s["record-unsealed"] = bytes([13, 1]) + bytes(range(60)) + START + valid_run(4)
    for k, v in s.items():
        put("guard", k, v)
        put("guard_fx", k, v)


# ------------------------------------------------------------------- link

def crc16(data):
    crc = 0xFFFF
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


def cobs(data):
    out = bytearray([0])
    code_pos, code = 0, 1
    for b in data:
        if b == 0:
            out[code_pos] = code
            code_pos = len(out)
            out.append(0)
            code = 1
        else:
            out.append(b)
            code += 1
            if code == 0xFF:
                out[code_pos] = code
                code_pos = len(out)
                out.append(0)
                code = 1
    out[code_pos] = code
    return bytes(out)


def frame(payload):
    return cobs(payload + struct.pack("<H", crc16(payload))) + b"\x00"


def request(seq, vals=(30.0, 65.0, 5.0, 500.0, 0.0, 16.0)):
    return frame(bytes([1]) + struct.pack("<H", seq & 0xFFFF) + struct.pack("<6f", *vals))


def link_seeds():
    s = {}
    s["raw-10-frames"] = b"\x00" + b"".join(request(i) for i in range(10))
    s["raw-gap-dup-old"] = b"\x00" + b"".join(request(i) for i in (5, 6, 6, 4, 9, 0x8009, 10))
    s["raw-wrap"] = b"\x00" + b"".join(request(i) for i in (65534, 65535, 0, 1))
    bad = bytearray(request(3))
    bad[5] ^= 0x10
    s["raw-crc-error"] = b"\x00" + request(1) + request(2) + bytes(bad) + request(4)
    s["raw-truncated"] = b"\x00" + request(1) + request(2)[:9] + b"\x00" + request(3)
    s["raw-overflow"] = b"\x00" + b"\x55" * 300 + b"\x00" + request(1)
    s["raw-empty-frames"] = b"\x00" + b"\x00\x00\x00" + request(1) + b"\x00\x00"
    s["raw-nan"] = b"\x00" + request(1) + request(2, (float("nan"), 65.0, 5.0, 500.0, 0.0, 16.0)) + request(3)
    s["raw-wrong-kind"] = b"\x00" + frame(bytes([0x81]) + bytes(36)) + frame(bytes([7]) + bytes(26))
    s["raw-short-payload"] = b"\x00" + frame(bytes([1, 0, 0])) + frame(b"\x01")
    s["raw-cobs-bad"] = b"\x00" + bytes([5, 1, 2, 0]) + bytes([0xFF] + [1] * 10 + [0])
    # structured mode (odd mode byte): seq then ops (selector, values, corruption)
    ops = bytearray(b"\x01" + struct.pack("<H", 100))
    for i in range(40):
        sel = i % 8 | (0x10 if i % 3 == 0 else 0)
        ops += bytes([sel])
        if sel % 8 in (5, 6, 7):
            ops += bytes([3])
        ops += bytes([i * 7 % 256, i * 13 % 256, 3, 250, 9, 1])
        if sel & 0x10:
            ops += bytes([i % 10, 17, 3])
    s["structured-mix"] = bytes(ops)
    s["structured-raw-values"] = b"\x0b" + struct.pack("<H", 7) + (bytes([0x08]) + struct.pack("<6f", 1.0, float("inf"), -1.0, 1e9, 0.0, -273.0)) * 8
    s["reply-payload"] = b"\x00" + bytes([0x82, 1, 0, 6]) + bytes(33)
    for k, v in s.items():
        put("link", k, v)


# ------------------------------------------------------------ host readers

def measured_seeds():
    h = "time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,t_oil_c\n"
    meta = "# rig: bench-A\n# case: 1\n# free text without key\n"
    s = {}
    with open(os.path.join(ROOT, "docs/examples/diagnosis/measured.csv")) as f:
        s["example-head"] = "".join(f.readlines()[:12])
    s["full-columns"] = ("time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,position_mm,t_motor_c,t_pump_c,"
                         "t_block_c,t_ballvalve_c,t_oil_c,t_drain_c,lng_valve,air_speed_mps\n"
                         "0,500,12,60,1,16,0,20,21,22,23,24,25,0,0\n0.1,-500,12,60,1,16,-10,20,21,22,23,24,25,1,15\n")
    s["missing-cells-unknown-col"] = meta + "time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,vendor_x,t_oil_c\n0.0,500,12.5,60,1,16,abc,20.0\n0.5,500,,60,1,16,, \n1.0,-500,12.5,60,1,16,x,20.25\n"
    s["bom-crlf"] = "\ufeff" + h.replace("\n", "\r\n") + "0,1,2,3,4,5,6\r\n1,1,2,3,4,5,6\r\n"
    s["nan"] = meta + h + "0,500,10,60,1,16,NaN\n"
    s["inf"] = meta + h + "0,500,10,60,1,inf,20\n"
    s["time-not-increasing"] = meta + h + "0,500,10,60,1,16,20\n0,500,10,60,1,16,20\n"
    s["missing-time"] = meta + h + ",500,10,60,1,16,20\n"
    s["out-of-range"] = meta + h + "0,500,10,900,1,16,20\n"
    s["unparsable"] = meta + h + "0,500,10,6O,1,16,20\n"
    s["short-row"] = meta + h + "0,500,10\n"
    s["duplicate-col"] = "time_s,speed_rpm,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c\n0,1,1,1,1,1,1\n"
    s["missing-col"] = "time_s,speed_rpm,p_a_bar,p_b_bar,ambient_c\n0,1,1,1,1\n"
    s["quoted"] = meta + h + '"0","500",10,60,1,16,"2""0"\n'
    s["no-header"] = "# only metadata\n\n"
    s["exp-notation"] = h + "1e-3,5e2,1.25E1,6e1,1,1.6e1,2e1\n2e-3,+5e2,.5,60.,1,16,20\n"
    for k, v in s.items():
        put("measured_csv", k, v)


def mission_seeds():
    h = "time_s,speed_rpm,needle_bar,position_mm,ambient_c,air_speed_mps\n"
    s = {}
    s["throttle"] = h + "0,500,0,,16,0\n100,500,60,,16,0\n100,500,20,,16,15\n600,0,0,,20,30\n"
    s["servo"] = "# servo mission\n" + h + "0,,,0,26.4,\n2.5,,,20,26.4,\n5,,,-20,26.4,\n10,,,0,26.4,\n"
    s["not-increasing"] = h + "0,500,0,,16,0\n-1,500,0,,16,0\n"
    s["nan-time"] = h + "NaN,500,0,,16,0\n"
    s["missing-ambient"] = h + "0,500,0,,,0\n"
    s["no-rows"] = h
    s["reordered-extra"] = "ambient_c,time_s,speed_rpm,extra\n16,0,500,x\n17,1,400,y\n"
    s["spaces"] = " time_s , speed_rpm ,needle_bar,position_mm, ambient_c ,air_speed_mps\n 0 , 500 ,1,, 16 ,\n"
    s["bad-number"] = h + "0,fast,0,,16,0\n"
    s["inf"] = h + "0,inf,0,,16,0\n1e308,1,1,1,1,1\n"
    for k, v in s.items():
        put("mission_csv", k, v)


def rig_seeds():
    with open(os.path.join(ROOT, "host-tests/rig/liu2024.toml")) as f:
        rig = f.read()
    s = {}
    s["liu2024"] = rig
    s["ext-on"] = rig.replace("[ext]", "[ext]\nsensor_lag = 60.0\nchurning_loss = 1e-6\nviscosity_temperature = true") if "[ext]" in rig else rig + "\n[ext]\nsensor_lag = 60.0\nviscosity_temperature = true\n"
    s["override-line"] = "pump.gaps.piston_gap_m=10e-6\n"
    s["override-none"] = "ext.sensor_lag=none\n"
    s["unknown-field"] = rig.replace("[motor]", "[motor]\nbogus = 1", 1)
    s["negative"] = rig.replace("r25_ohm = 0.074", "r25_ohm = -0.074")
    s["nan"] = rig.replace("r25_ohm = 0.074", "r25_ohm = nan")
    s["truncated"] = rig[: len(rig) // 2]
    s["nested"] = "a = [[[[[[[[[[1]]]]]]]]]]\nb = { c = { d = { e = 1 } } }\n"
    for k, v in s.items():
        put("rig_toml", k, v)


if __name__ == "__main__":
    guard_seeds()
    link_seeds()
    measured_seeds()
    mission_seeds()
    rig_seeds()
