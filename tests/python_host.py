"""A Python process that hosts the Python FMU and reports what the FMU changed in it.

    python python_host.py FMU [FAKE_LCVREPORT_PARENT]

With a second argument, a different ``lcvreport`` (a stand-in package) is imported first.
The FMU is driven through ctypes alone (no fmpy: the process may have no numpy of its own,
``python -S``).  Prints one JSON line: ok, the steps' outputs, and what differs in sys.path,
sys.meta_path, sys.path_hooks and __main__'s names after fmi2FreeInstance.
"""
import ctypes
import json
import os
import sys
import tempfile
import zipfile

def main():
    fmu = sys.argv[1]
    if len(sys.argv) > 2:
        sys.path.insert(0, sys.argv[2])
        import lcvreport  # noqa: F401  (the stand-in)
        sys.path.remove(sys.argv[2])
    before = {"path": list(sys.path), "meta": [repr(f) for f in sys.meta_path], "hooks": [repr(h) for h in sys.path_hooks],
              "main": sorted(vars(sys.modules["__main__"]))}
    d = tempfile.mkdtemp()
    zipfile.ZipFile(fmu).extractall(d)
    import xml.etree.ElementTree as ET  # noqa: E402
    root = ET.parse(os.path.join(d, "modelDescription.xml")).getroot()
    ident = root.find("CoSimulation").get("modelIdentifier")
    vr = {sv.get("name"): int(sv.get("valueReference")) for sv in root.iter("ScalarVariable")}
    lib = ctypes.CDLL(os.path.join(d, "binaries", "linux64", ident + ".so"))
    messages = []
    LOGGER = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p)
    libc = ctypes.CDLL(None)
    libc.calloc.restype = ctypes.c_void_p
    libc.calloc.argtypes = [ctypes.c_size_t, ctypes.c_size_t]
    libc.free.argtypes = [ctypes.c_void_p]
    ALLOC = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_size_t, ctypes.c_size_t)
    FREE = ctypes.CFUNCTYPE(None, ctypes.c_void_p)


    class Callbacks(ctypes.Structure):
        _fields_ = [("logger", LOGGER), ("allocateMemory", ALLOC), ("freeMemory", FREE),
                    ("stepFinished", ctypes.c_void_p), ("componentEnvironment", ctypes.c_void_p)]


    keep = [LOGGER(lambda env, name, status, cat, msg: messages.append((status, (msg or b"").decode()))),
            ALLOC(lambda n, size: libc.calloc(n, size)), FREE(lambda p: libc.free(p))]
    cb = Callbacks(keep[0], keep[1], keep[2], None, None)
    lib.fmi2Instantiate.restype = ctypes.c_void_p
    lib.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p,
                                    ctypes.POINTER(Callbacks), ctypes.c_int, ctypes.c_int]
    for f in ("fmi2SetupExperiment", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2DoStep",
              "fmi2Terminate", "fmi2SetReal", "fmi2GetReal"):
        getattr(lib, f).restype = ctypes.c_int
    lib.fmi2FreeInstance.argtypes = [ctypes.c_void_p]
    uri = ("file://" + os.path.join(d, "resources")).encode()
    c = lib.fmi2Instantiate(b"host", 1, root.get("guid").encode(), uri, ctypes.byref(cb), 0, 1)
    out = {"ok": bool(c), "messages": [m for s, m in messages if s >= 3]}
    if c:
        c = ctypes.c_void_p(c)
        lib.fmi2SetupExperiment(c, 0, ctypes.c_double(0.0), ctypes.c_double(0.0), 0, ctypes.c_double(0.0))
        lib.fmi2EnterInitializationMode(c)
        lib.fmi2ExitInitializationMode(c)
        refs = (ctypes.c_uint * 1)(vr["delta"])
        lib.fmi2SetReal(c, refs, 1, (ctypes.c_double * 1)(0.01))
        for k in range(10):
            lib.fmi2DoStep(c, ctypes.c_double(0.1 * k), ctypes.c_double(0.1), 1)
        val = (ctypes.c_double * 1)()
        lib.fmi2GetReal(c, (ctypes.c_uint * 1)(vr["r1"]), 1, val)
        out["r1"] = val[0]
        lib.fmi2Terminate(c)
        lib.fmi2FreeInstance(c)
    after = {"path": list(sys.path), "meta": [repr(f) for f in sys.meta_path], "hooks": [repr(h) for h in sys.path_hooks],
             "main": sorted(vars(sys.modules["__main__"]))}
    out["changed"] = {k: [x for x in after[k] if x not in before[k]] + [f"-{x}" for x in before[k] if x not in after[k]]
                      for k in before if k != "main"}
    out["main_added"] = [n for n in after["main"] if n not in before["main"] and n not in (
        "after", "out", "val", "refs", "k", "c", "cb", "keep", "uri", "d", "root", "ident", "vr", "lib", "messages",
        "LOGGER", "libc", "ALLOC", "FREE", "Callbacks", "ET", "f", "before")]
    out["lcvreport"] = getattr(sys.modules.get("lcvreport"), "__file__", None)
    out["numpy_from"] = getattr(sys.modules.get("numpy"), "__file__", None)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
