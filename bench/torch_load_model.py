#!/usr/bin/python3
"""Loads a HADYNET model file into PyTorch and checks it against `hadynet simulate`.

Checks that the safetensors model written by the C++ trainer (docs/model-file.md)
has exactly the state_dict names, shapes and layouts of the PyTorch module in
bench/torch_baseline.py (load_state_dict with strict=True), then predicts the
same rollout as `hadynet simulate` and prints the largest difference.

Usage: /usr/bin/python3 bench/torch_load_model.py MODEL LOG SIMULATED_CSV --pb STATE --from T
  SIMULATED_CSV is the output of
  `hadynet simulate MODEL --log LOG --pb STATE --from T --horizon N --out SIMULATED_CSV`.
Needs python3-torch and python3-numpy (scripts/setup.sh --bench).
"""
import argparse
import json
import struct
import sys

import numpy as np
import torch

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from torch_baseline import Hadynet, read_log  # noqa: E402

DTYPES = {"F32": "<f4", "F64": "<f8", "I32": "<i4", "I64": "<i8", "U8": "u1"}


def read_safetensors(path):
    with open(path, "rb") as f:
        data = f.read()
    n = struct.unpack("<Q", data[:8])[0]
    header = json.loads(data[8:8 + n])
    meta = header.pop("__metadata__", {})
    base = 8 + n
    tensors = {}
    for name, t in header.items():
        b, e = t["data_offsets"]
        tensors[name] = np.frombuffer(data[base + b:base + e], dtype=DTYPES[t["dtype"]]).reshape(t["shape"])
    return meta, tensors


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model")
    ap.add_argument("log")
    ap.add_argument("simulated")
    ap.add_argument("--pb", required=True, help="state name of the model's PB table")
    ap.add_argument("--from", dest="start", type=int, required=True, help="start step t of the rollout")
    a = ap.parse_args()

    meta, t = read_safetensors(a.model)
    dims = json.loads(meta["dims"])
    channels = json.loads(meta["channels"])
    states = [s["name"] for s in json.loads(meta["states"])]
    net = Hadynet(dims["x"], dims["u"], dims["y"], dims["states"], dims["pb"], dims["hidden"])
    state_dict = {k: torch.from_numpy(v.copy()) for k, v in t.items() if not k.startswith(("norm.", "detect."))}
    net.load_state_dict(state_dict, strict=True)  # names, shapes, nothing missing or extra
    net.eval()

    header, values = read_log(a.log)
    col = {name: i for i, name in enumerate(header)}
    sim_header, sim = read_log(a.simulated)
    steps = sim.shape[0]
    t0 = a.start

    def x_at(r):
        out = []
        for name in channels["x"]:
            if name in col:
                out.append(values[r, col[name]])
            else:  # "d<channel>": step difference
                c = col[name[1:]]
                out.append(values[r, c] - values[r - 1, c])
        return np.array(out)

    x0 = (x_at(t0) - t["norm.x_mean"]) / t["norm.x_std"]
    u = np.stack([values[t0 + k, [col[n] for n in channels["u"]]] for k in range(steps)])
    u = (u - t["norm.u_mean"]) / t["norm.u_std"]
    with torch.no_grad():
        y = net(torch.tensor(x0[None], dtype=torch.float32), torch.tensor(u[None], dtype=torch.float32),
                torch.tensor([states.index(a.pb)]))[0].double().numpy()
    y = y * t["norm.y_std"] + t["norm.y_mean"]
    ours = sim[:, [sim_header.index(n) for n in channels["y"]]]
    diff = np.abs(y - ours)
    rel = diff / (np.abs(ours).max(axis=0) + 1e-12)
    print(f"PyTorch loaded {a.model} with strict=True ({len(state_dict)} tensors)")
    print(f"{steps}-step rollout vs hadynet simulate: max |diff| {diff.max():.3g} (physical units), "
          f"max relative to channel range {rel.max():.3g}")
    return 0 if rel.max() < 1e-4 else 1


if __name__ == "__main__":
    sys.exit(main())
