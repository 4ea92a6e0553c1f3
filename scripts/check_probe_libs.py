#!/usr/bin/env python3
"""Fails unless the many-core probe (octiso-probe, issue 12) needs no shared library beyond TBB,
Embree and the C/C++ runtimes: it must run on a machine that has nothing installed, carried with
those two (scripts/manycore_probe.sh pack). Reads the binary's DT_NEEDED entries with readelf."""
import re
import subprocess
import sys

# The C/C++ runtimes, and the sanitizer runtimes of an ASan/UBSan/TSan build (the compiler's own;
# the probe that travels is a Release build).
ALLOWED = re.compile(r"^(libtbb|libembree|libc\.so|libm\.so|libstdc\+\+|libgcc_s|libpthread|libdl|librt|ld-linux|"
                     r"libasan|libubsan|libtsan)")


def main(binary):
    out = subprocess.run(["readelf", "-d", binary], check=True, capture_output=True, text=True).stdout
    needed = re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out)
    if not needed:
        print(f"{binary}: no NEEDED entries read (not a dynamic ELF?)")
        return 1
    extra = [n for n in needed if not ALLOWED.match(n)]
    print(f"{binary} needs: {', '.join(needed)}")
    if extra:
        print(f"FAIL: the probe needs more than TBB and Embree: {', '.join(extra)}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
