#!/usr/bin/python3
"""check_isa.py BINARY...: the portable code of a built tool holds no AVX instruction.

The traversal is compiled twice (src/util/isa.h): the portable kernel with the project's
x86-64-v2 flags, and src/render/kernel_avx2.cpp with -mavx2 -mfma in the inline namespace
isa_avx2. If the linker merged an inline function or template instantiation of the AVX2 unit
into the portable path, a CPU without AVX2 would die of an illegal instruction. This disassembles
each binary and fails on any function outside isa_avx2 (and its entry points,
make_tracer_kernel_avx2) that contains a VEX or EVEX encoded instruction (mnemonics v*), and
when no isa_avx2 function exists at all (the kernel must be there to be chosen).
"""
import re
import subprocess
import sys

# VEX/EVEX mnemonics all start with "v"; the few legacy ones that do too are not vector code.
LEGACY_V = {"verr", "verw", "vmcall", "vmlaunch", "vmresume", "vmxoff", "vmxon", "vmread", "vmwrite",
            "vmptrld", "vmptrst", "vmclear", "vmfunc", "vmrun", "vmload", "vmsave", "vmmcall"}
ALLOWED = ("isa_avx2", "make_tracer_kernel_avx2")


def check(binary):
    out = subprocess.run(["objdump", "-d", "--no-show-raw-insn", "-C", binary], check=True,
                         capture_output=True, text=True).stdout
    func, bad, kernel_functions = None, {}, 0
    for line in out.splitlines():
        m = re.match(r"^[0-9a-f]+ <(.*)>:$", line)
        if m:
            func = m.group(1)
            if "isa_avx2" in func:
                kernel_functions += 1
            continue
        parts = line.split("\t")
        if len(parts) < 2 or func is None:
            continue
        mnemonic = parts[1].split()[0] if parts[1].split() else ""
        if mnemonic.startswith("v") and mnemonic not in LEGACY_V and not any(a in func for a in ALLOWED):
            bad[func] = bad.get(func, 0) + 1
    ok = True
    if bad:
        ok = False
        print(f"{binary}: {len(bad)} function(s) outside isa_avx2 contain AVX instructions:")
        for f, n in sorted(bad.items(), key=lambda kv: -kv[1])[:20]:
            print(f"  {n:5d}  {f}")
    if kernel_functions == 0:
        ok = False
        print(f"{binary}: no isa_avx2 function: the AVX2 kernel is missing")
    if ok:
        print(f"{binary}: portable code is AVX-free; {kernel_functions} isa_avx2 functions")
    return ok


if len(sys.argv) < 2:
    sys.exit(__doc__)
sys.exit(0 if all([check(b) for b in sys.argv[1:]]) else 1)
