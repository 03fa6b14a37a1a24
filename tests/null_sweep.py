"""Call every exported FMI function of an FMU binary with a NULL instance and zero arguments.

    python null_sweep.py LIBRARY.so fmi2|fmi3

Prints one JSON line {function: status}; a crash shows as a missing line."""
import ctypes
import json
import re
import sys
from pathlib import Path


def main():
    lib_path, version = sys.argv[1], sys.argv[2]
    import fmpy
    header = (Path(fmpy.__file__).parent / "c-code" / f"{version}FunctionTypes.h").read_text()
    header = re.sub(r"/\*.*?\*/", "", header, flags=re.S)
    lib = ctypes.CDLL(lib_path)
    out = {}
    for m in re.finditer(r"typedef\s+([\w\s\*]+?)\s*\(?\s*(fmi[23]\w+)TYPE\s*\)?\s*\((.*?)\);", header, re.S):
        ret, name, params = m.group(1).strip(), m.group(2), " ".join(m.group(3).split())
        if not hasattr(lib, name) or name.startswith(("fmi2Instantiate", "fmi3Instantiate")) or params == "void":
            continue
        f = getattr(lib, name)
        nargs = len([p for p in params.split(",") if p.strip()])
        f.argtypes = [ctypes.c_void_p] * nargs
        f.restype = ctypes.c_int if ret.endswith("Status") else ctypes.c_void_p
        out[name] = f(*([None] * nargs))
    print(json.dumps(out))


if __name__ == "__main__":
    main()
