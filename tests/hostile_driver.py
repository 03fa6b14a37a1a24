"""One hostile call sequence against one FMU in fmpy, in a process of its own.

    python hostile_driver.py FMU CASE

Prints one JSON line: the status of every call (fmpy raises for statuses above
fmi2Warning; the status is recorded), the log messages with status >= fmi2Warning,
whether every output read was finite; then the instance is freed, the garbage is
collected and "survived" is printed.  A host crash shows as a missing "survived".
"""
from __future__ import annotations

import ctypes
import gc
import json
import math
import sys

from fmpy.fmi2 import fmi2FMUstate

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from fmu_support import Slave  # noqa: E402

STATUS = []
FINITE = [True]


def call(f, *args):
    try:
        out = f(*args)
        STATUS.append(0)
        return out
    except Exception as exc:  # fmpy's FMICallException carries .status
        STATUS.append(int(getattr(exc, "status", 99)))
        return None


def read(s):
    values = call(s.fmu.getReal, [s.vr[n] for n in s.outputs])
    if values is not None:
        FINITE[0] = FINITE[0] and all(math.isfinite(v) for v in values)


def step(s, h=0.01):
    call(s.fmu.doStep, 0.0, h)


def main(path: str, case: str) -> None:
    start = {}
    if case == "bad_preset":
        start = {"preset": "AUCNAT"}
    elif case == "tire_scale_huge":
        start = {"tire_scale": 1e300}
    elif case == "tire_scale_tiny":
        start = {"tire_scale": 1e-300}
    elif case == "u_min_huge":
        start = {"u_min": 1e300}
    elif case == "tire_scale_nan":
        start = {"tire_scale": float("nan")}
    s = Slave(path, **start)
    if case in ("set_integer_range_0", "set_integer_range_7", "set_integer_real"):     # preset: 1 to 6
        vr, value = ([s.vr["tire_scale"]], [2]) if case == "set_integer_real" else ([s.vr["preset"]], [int(case[-1])])
        call(s.fmu.setInteger, vr, value)
        call(s.fmu.exitInitializationMode)                           # the start value stays: aucnat
        step(s)
        read(s)
    elif case in ("bad_preset", "tire_scale_huge", "tire_scale_tiny", "u_min_huge", "tire_scale_nan"):
        call(s.fmu.exitInitializationMode)
        step(s)
        read(s)
    else:
        s.init()
        if case == "unknown_vr":
            call(s.fmu.getReal, [9999])
        elif case == "set_output":
            call(s.fmu.setReal, [s.vr["y2"]], [1.0])
        elif case in ("u_1e308", "u_1e20", "u_nan", "u_inf"):
            value = {"u_1e308": 1e308, "u_1e20": 1e20, "u_nan": float("nan"), "u_inf": float("inf")}[case]
            call(s.fmu.setReal, [s.vr["u"]], [value])
            step(s)
            call(s.fmu.setReal, [s.vr["u"]], [22.352])
            step(s)
            read(s)
        elif case == "delta_1e308":
            call(s.fmu.setReal, [s.vr["delta"]], [1e308])
            step(s)
            call(s.fmu.setReal, [s.vr["delta"]], [0.0])
            step(s)
            read(s)
        elif case == "force_nan":
            name = [v.name for v in s.itf.inputs if v.source[0] == "P"][0]
            call(s.fmu.setReal, [s.vr[name]], [float("nan")])
            step(s)
            read(s)
        elif case in ("step_zero", "step_nan", "step_negative", "step_huge"):
            h = {"step_zero": 0.0, "step_nan": float("nan"), "step_negative": -1.0, "step_huge": 1e10}[case]
            step(s, h)
            step(s)
            read(s)
        elif case in ("deserialize_garbage", "deserialize_empty"):
            data = bytes(range(256)) * 4 if case == "deserialize_garbage" else b""
            call(s.fmu.deserializeFMUState, data)
            step(s)
        elif case == "deserialize_null":
            state = fmi2FMUstate()
            call(s.fmu.fmi2DeSerializeFMUstate, s.fmu.component, None, 100, ctypes.byref(state))
        elif case == "state_with_nan":
            step(s)
            state = s.fmu.getFMUState()
            data = bytearray(s.fmu.serializeFMUState(state))
            if data.startswith(b"lcv-fmu-state/1"):     # pythonfmu FMU: JSON after a magic line, phase byte
                head, body = bytes(data[:-1]).split(b"\n", 1)
                doc = json.loads(body)
                doc["engine"]["z"][0] = float("nan")
                data = bytearray(head + b"\n" + json.dumps(doc).encode() + bytes(data[-1:]))
            else:                                      # C FMU: z[0] of the snapshot set to NaN
                offset = 4 + 4 + 64 + 64 + 16 + 8 * len(s.itf.inputs)   # magic, size, guid, preset, params, w
                data[offset:offset + 8] = bytes(bytearray(ctypes.c_double(float("nan"))))
            restored = call(s.fmu.deserializeFMUState, bytes(data))
            if restored is not None:
                call(s.fmu.setFMUState, restored)
            step(s)
            read(s)
        elif case == "state_of_another_fmu":
            other = Slave(sys.argv[3]).init()
            state = other.fmu.getFMUState()
            call(s.fmu.setFMUState, state)
            other.fmu.freeFMUState(state)
            other.free()
            step(s)
        elif case == "exit_init_twice":
            step(s)
            call(s.fmu.exitInitializationMode)
        elif case == "fixed_parameter_after_init":
            call(s.fmu.setReal, [s.vr["tire_scale"]], [2.0])
        elif case == "get_integer":
            call(s.fmu.getInteger, [1])                   # tire_scale: a Real
        elif case == "set_integer_after_init":
            call(s.fmu.setInteger, [0], [2])
        else:
            raise SystemExit(f"unknown case {case}")
    messages = s.log.messages(1)
    s.free()
    del s
    gc.collect()
    print(json.dumps({"status": STATUS, "messages": messages, "finite": FINITE[0]}))
    print("survived")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
