#!/usr/bin/python3
"""plot.py KIND RESULT.json OUT.png: draws one benchmark's result; KIND names bench/plots/KIND.py,
which defines plot(data, out_png). Uses Debian's python3-matplotlib (call /usr/bin/python3)."""
import importlib.util
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")

if len(sys.argv) != 4:
    sys.exit(__doc__)
kind, json_path, png_path = sys.argv[1:]
module_path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "plots", kind + ".py")
spec = importlib.util.spec_from_file_location(kind, module_path)
if spec is None or not os.path.exists(module_path):
    sys.exit(f"plot.py: no plotter {module_path}")
module = importlib.util.module_from_spec(spec)
spec.loader.exec_module(module)
with open(json_path) as f:
    module.plot(json.load(f), png_path)
