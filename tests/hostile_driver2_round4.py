"""Round-four hostile calls against an FMI 2.0 FMU (native or Python), in a process of its own.

    python hostile_driver2_round4.py FMU CASE

Raw ctypes calls (an instance name that is not UTF-8, Model Exchange FMU states, a
Co-Simulation state set into a Model Exchange instance, directional derivatives in
Initialization Mode, a clamped step); prints one JSON line (statuses, messages) and then
"survived": the host was not taken down.
"""
import ctypes
import json
import os
import sys
import tempfile
import urllib.parse
import xml.etree.ElementTree as ET
import zipfile

V = ctypes.c_void_p
LOGGER = ctypes.CFUNCTYPE(None, V, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p)
ALLOC = ctypes.CFUNCTYPE(V, ctypes.c_size_t, ctypes.c_size_t)
FREE = ctypes.CFUNCTYPE(None, V)


class Callbacks(ctypes.Structure):
    _fields_ = [("logger", LOGGER), ("allocateMemory", ALLOC), ("freeMemory", FREE), ("stepFinished", V),
                ("componentEnvironment", V)]


def main():
    fmu, case = sys.argv[1], sys.argv[2]
    d = tempfile.mkdtemp()
    zipfile.ZipFile(fmu).extractall(d)
    root = ET.parse(os.path.join(d, "modelDescription.xml")).getroot()
    ident = (root.find("CoSimulation") if root.find("CoSimulation") is not None else root.find("ModelExchange"))\
        .get("modelIdentifier")
    guid = root.get("guid").encode()
    vr = {e.get("name"): int(e.get("valueReference")) for e in root.find("ModelVariables")}
    lib = ctypes.CDLL(os.path.join(d, "binaries", "linux64", ident + ".so"))
    uri = ("file://" + urllib.parse.quote(os.path.join(d, "resources"))).encode()
    records, statuses = [], []
    libc = ctypes.CDLL(None)
    libc.calloc.restype, libc.calloc.argtypes = V, [ctypes.c_size_t, ctypes.c_size_t]
    libc.free.argtypes = [V]

    @LOGGER
    def log(_env, _name, status, _category, message):
        records.append((status, (message or b"").decode("utf-8", "replace")))
    cb = Callbacks(log, ALLOC(libc.calloc), FREE(libc.free), None, None)

    def fn(name, restype, *argtypes):
        f = getattr(lib, name)
        f.restype, f.argtypes = restype, list(argtypes)
        return f

    def call(name, argtypes, *args):
        s = fn(name, ctypes.c_int, *argtypes)(*args)
        statuses.append(s)
        return s
    D, U, S = ctypes.c_double, ctypes.c_uint, ctypes.c_size_t
    inst = fn("fmi2Instantiate", V, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p,
              ctypes.POINTER(Callbacks), ctypes.c_int, ctypes.c_int)

    def instantiate(kind=1, name=b"h"):             # 0: Model Exchange, 1: Co-Simulation
        return inst(name, kind, guid, uri, ctypes.byref(cb), 0, 0)

    def init(c):
        call("fmi2SetupExperiment", [V, ctypes.c_int, D, D, ctypes.c_int, D], c, 0, 0.0, 0.0, 0, 0.0)
        call("fmi2EnterInitializationMode", [V], c)
        call("fmi2ExitInitializationMode", [V], c)

    def arr(ctype, *values):
        return (ctype * max(1, len(values)))(*values)

    free = fn("fmi2FreeInstance", None, V)
    c = None
    if case == "instance_name_not_utf8":
        c = instantiate(name=b"Fahrzeug \xfcber \xff\xfe")
        statuses.append(0 if c else 3)
        if c:
            init(c)
            call("fmi2DoStep", [V, D, D, ctypes.c_int], c, 0.0, 0.01, 1)
    elif case == "me_state_round_trip":
        c = instantiate(0)
        assert c, records
        init(c)
        call("fmi2EnterContinuousTimeMode", [V], c)
        nx = int(root.find("ModelStructure").find("Derivatives").__len__())
        x = arr(D, *[0.001 * (k + 1) for k in range(nx)])
        call("fmi2SetContinuousStates", [V, V, S], c, x, nx)
        state = V()
        call("fmi2GetFMUstate", [V, V], c, ctypes.byref(state))
        call("fmi2SetContinuousStates", [V, V, S], c, arr(D, *[0.0] * nx), nx)
        call("fmi2SetFMUstate", [V, V], c, state)
        back = arr(D, *[0.0] * nx)
        call("fmi2GetContinuousStates", [V, V, S], c, back, nx)
        records.append((0, f"restored={list(back[:nx]) == list(x[:nx])}"))
        call("fmi2FreeFMUstate", [V, V], c, ctypes.byref(state))
    elif case == "cs_state_into_me":
        cs = instantiate(1)
        init(cs)
        call("fmi2DoStep", [V, D, D, ctypes.c_int], cs, 0.0, 0.01, 1)
        state = V()
        call("fmi2GetFMUstate", [V, V], cs, ctypes.byref(state))
        c = instantiate(0)
        init(c)
        call("fmi2SetFMUstate", [V, V], c, state)
        call("fmi2DoStep", [V, D, D, ctypes.c_int], c, 0.0, 0.01, 1)
        call("fmi2FreeFMUstate", [V, V], cs, ctypes.byref(state))
        free(cs)
    elif case == "directional_in_init":
        c = instantiate(1)
        call("fmi2SetupExperiment", [V, ctypes.c_int, D, D, ctypes.c_int, D], c, 0, 0.0, 0.0, 0, 0.0)
        call("fmi2EnterInitializationMode", [V], c)
        dd = [V, V, S, V, S, V, V]
        out = arr(D, 0.0)
        call("fmi2GetDirectionalDerivative", dd, c, arr(U, vr["r1"]), 1, arr(U, vr["u"]), 1, arr(D, 1.0), out)
        call("fmi2GetDirectionalDerivative", dd, c, arr(U, vr["max_real_eig"]), 1, arr(U, vr["delta"]), 1,
             arr(D, 1.0), out)
        call("fmi2GetDirectionalDerivative", dd, c, arr(U, 99999), 1, arr(U, vr["delta"]), 1, arr(D, 1.0), out)
        call("fmi2GetDirectionalDerivative", dd, c, arr(U, vr["r1"]), 1, arr(U, vr["delta"]), 1, arr(D, 1.0), out)
    elif case == "clamped_step_status":
        c = instantiate(1)
        call("fmi2SetReal", [V, V, S, V], c, arr(U, vr["u"]), 1, arr(D, 0.5))
        init(c)
        call("fmi2DoStep", [V, D, D, ctypes.c_int], c, 0.0, 0.01, 1)
        call("fmi2DoStep", [V, D, D, ctypes.c_int], c, 0.01, 0.01, 1)
    else:
        raise SystemExit(f"unknown case {case}")
    if c:
        free(c)
    print(json.dumps({"status": statuses, "messages": [m for s, m in records if s >= 1 or m.startswith("restored=")],
                      "fatal": any(s == 4 for s, _m in records) or 4 in statuses}))
    print("survived")


if __name__ == "__main__":
    main()
