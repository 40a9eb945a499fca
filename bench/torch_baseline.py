#!/usr/bin/python3
"""PyTorch baseline for the benchmark "seconds per training epoch, ours vs PyTorch".

This script trains HADYNET in PyTorch (written for torch 1.13, Debian 12's
python3-torch) with the same network, the same data and the same training
procedure as the C++ trainer (trainer/), and reports the wall time of each
training epoch. The benchmark's figure is the ratio of the C++ trainer's
seconds per epoch to this script's median seconds per epoch.

Correspondence with the C++ trainer
-----------------------------------
Data (dataset folder from `hadynet collect`, default data/paper):
  * logs: the entries of manifest.json with split == "train".
  * log format (docs/log-format.md): '#' metadata lines, one CSV header, numeric
    rows. Channels are grouped by name prefix (the letters before the index),
    groups in order of first appearance, channels of a group in header order.
    `t` and `aux_*` columns are ignored. Observed groups (y) = every numbered
    group except `u`; commands = group `u`. Sizes come from the header, never
    hard-coded (paper: y 27 = l8 f8 fc9 th2, u 8, x 37).
  * features: y_t = observed channels of row t. x_t = for each observed group
    in order: its values at t, followed, for a "delta group" (default l and th,
    --delta-groups), by its values at t minus at t-1.
    Paper: x = (l, dl, f, fc, th, dth) = 37 channels.
  * windows: N = --steps (10) steps, one per start row i = 1 .. T-1-N inclusive
    (T = rows of the log): input x_i, commands u_i .. u_{i+N-1}, targets
    y_{i+1} .. y_{i+N}.
  * states: each window belongs to its log's manifest "state"; the distinct
    states are sorted by name and indexed 0 .. S-1 (row of the PB table).
  * standardisation: x, u and y per channel, (v - mean) / max(std, 1e-6), with
    mean and population std (ddof 0) over the training windows (x: each
    window's x_i; u, y: every step of every window). The C++ trainer takes the
    statistics over every row of the logs and floors a channel's std at 0.1 x
    its group's median (trainer/normalization.h); the difference changes the
    loss values, not the work per epoch that this baseline times.
Network (PyTorch state_dict names = trainer/hadynet_params.h names):
  * pb = nn.Parameter(zeros(states, pb_dim)), pb_dim 8 (--pb); p = pb[state].
  * enc = nn.Linear(x + pb, hidden) on [x_i ; p]; enc_bn = nn.BatchNorm1d(hidden)
    (training mode: batch statistics, eps 1e-5, momentum 0.1); ReLU -> h_0;
    c_0 = 0. hidden 128 (--hidden).
  * lstm = nn.LSTM(u + pb, hidden), one layer, input at step k = [u_k ; p].
  * dec = nn.Linear(hidden, y) on every LSTM output h_{k+1} -> y_hat_{k+1}.
  * default PyTorch initialisation (Linear/LSTM uniform, BN weight 1 bias 0).
Training:
  * loss nn.MSELoss() (mean over steps, channels and windows), full BPTT.
  * torch.optim.Adam, lr 1e-3 (betas 0.9/0.999, eps 1e-8), over all parameters
    including pb.
  * batch 100 (--batch); windows shuffled each epoch by torch.randperm with a
    torch.Generator seeded from --seed; the last partial batch is kept unless
    it holds a single window (BatchNorm needs 2).
  * float32, torch.set_num_threads(--threads, default 2), no anomaly detection.
Timing:
  * one untimed warm-up batch (forward, backward, Adam step) first; the model
    and optimiser are then reset to their initial state, so the warm-up does
    not change the training run.
  * an epoch's seconds = wall time of its training loop only: batch gathering,
    forward, loss, backward and optimiser step. Data loading and
    standardisation are excluded.

Usage (with the Python that has python3-torch, i.e. Debian's /usr/bin/python3;
a pyenv or venv python3 earlier on PATH may not see it):
  python3 bench/torch_baseline.py [--data data/paper] [--epochs 3] [--threads 2]
      [--batch 100] [--window 10] [--hidden 128] [--pb-size 8] [--seed 1] [--json OUT]
"""

import argparse
import copy
import json
import os
import re
import statistics
import sys
import time

try:
    import numpy as np
    import torch
    import torch.nn as nn
except ImportError as e:
    sys.exit(f"{e}: run with the Python of python3-torch / python3-numpy, e.g. /usr/bin/python3")

CHANNEL_RE = re.compile(r"^([a-z]+)(0|[1-9][0-9]*)$")


# ----------------------------------------------------------------------------
# Environment


def loaded_blas():
    """Real path of the BLAS library torch loaded (Linux), or "unknown".

    Debian's python3-torch links libblas.so.3, which is whatever the
    libblas.so.3 alternative selects: the unoptimised single-threaded reference
    BLAS (libblas3) unless e.g. libopenblas0 is installed. That makes torch's
    matrix products several times slower, so it is printed and recorded.
    """
    try:
        with open("/proc/self/maps", "r", encoding="utf-8") as f:
            paths = {ln.split()[-1] for ln in f if "/" in ln}
    except OSError:
        return "unknown"
    for path in sorted(paths):
        base = os.path.basename(path)
        if any(k in base for k in ("blas", "mkl_rt", "blis")) and "cblas" not in base:
            return os.path.realpath(path)
    return "unknown"


def is_reference_blas(path):
    return path.endswith("/blas/libblas.so.3") or "/blas/libblas.so.3." in path


# ----------------------------------------------------------------------------
# Data


def read_log(path):
    """Returns (header names, values as float64 array rows x columns)."""
    with open(path, "r", encoding="utf-8") as f:
        lines = f.read().split("\n")
    k = 0
    while k < len(lines) and lines[k].startswith("#"):
        k += 1
    if k >= len(lines) or not lines[k]:
        raise ValueError(f"{path}: no header row")
    header = lines[k].split(",")
    rows = [ln for ln in lines[k + 1:] if ln]
    if not rows:
        raise ValueError(f"{path}: no data rows")
    values = np.array([r.split(",") for r in rows], dtype=np.float64)
    if values.ndim != 2 or values.shape[1] != len(header):
        raise ValueError(f"{path}: rows do not match the header ({len(header)} columns)")
    if not np.all(np.isfinite(values)):
        raise ValueError(f"{path}: non-finite value")
    return header, values


def channel_groups(header):
    """Ordered dict prefix -> list of column indices (t and aux_* skipped)."""
    groups = {}
    for col, name in enumerate(header):
        if name == "t" or name.startswith("aux_"):
            continue
        m = CHANNEL_RE.match(name)
        if not m:
            raise ValueError(f"unexpected column name '{name}'")
        groups.setdefault(m.group(1), []).append(col)
    return groups


def log_windows(header, values, delta_groups, steps):
    """x (W, x), u (W, N, u), y (W, N, y) float64 arrays of one log."""
    groups = channel_groups(header)
    observed = [g for g in groups if g != "u"]
    if not observed:
        raise ValueError("no observed channel group")
    if "u" not in groups:
        raise ValueError("no command group 'u'")
    y_cols = [c for g in observed for c in groups[g]]
    y_all = values[:, y_cols]
    u_all = values[:, groups["u"]]
    x_parts = []
    for g in observed:
        v = values[:, groups[g]]
        x_parts.append(v[1:])
        if g in delta_groups:
            x_parts.append(v[1:] - v[:-1])
    x_all = np.concatenate(x_parts, axis=1)  # row r holds x_{r+1}

    rows = values.shape[0]
    starts = np.arange(1, rows - steps)  # i = 1 .. T-1-N inclusive
    if starts.size == 0:
        return None
    k = np.arange(steps)
    x = x_all[starts - 1]
    u = u_all[starts[:, None] + k[None, :]]
    y = y_all[(starts + 1)[:, None] + k[None, :]]
    return x, u, y


def load_dataset(folder, delta_groups, steps):
    with open(os.path.join(folder, "manifest.json"), "r", encoding="utf-8") as f:
        manifest = json.load(f)
    logs = [e for e in manifest["logs"] if e.get("split") == "train"]
    if not logs:
        raise ValueError(f"{folder}: no train logs in manifest.json")
    states = sorted({e["state"] for e in logs})
    state_index = {s: k for k, s in enumerate(states)}

    xs, us, ys, ss = [], [], [], []
    ref_header = None
    for e in logs:
        header, values = read_log(os.path.join(folder, e["file"]))
        kept = [h for h in header if h != "t" and not h.startswith("aux_")]
        if ref_header is None:
            ref_header = kept
        elif kept != ref_header:
            raise ValueError(f"{e['file']}: channels differ from the first train log")
        w = log_windows(header, values, delta_groups, steps)
        if w is None:
            continue
        xs.append(w[0])
        us.append(w[1])
        ys.append(w[2])
        ss.append(np.full(w[0].shape[0], state_index[e["state"]], dtype=np.int64))
    x = np.concatenate(xs)
    u = np.concatenate(us)
    y = np.concatenate(ys)
    s = np.concatenate(ss)
    return x, u, y, s, states, len(logs)


def standardise(a):
    """Per channel (last axis), over every other axis: (a - mean) / max(std, 1e-6)."""
    flat = a.reshape(-1, a.shape[-1])
    mean = flat.mean(axis=0)
    std = np.maximum(flat.std(axis=0), 1e-6)
    return ((a - mean) / std).astype(np.float32)


# ----------------------------------------------------------------------------
# Network


class Hadynet(nn.Module):
    def __init__(self, x_dim, u_dim, y_dim, states, pb_dim, hidden):
        super().__init__()
        self.enc = nn.Linear(x_dim + pb_dim, hidden)
        self.enc_bn = nn.BatchNorm1d(hidden)
        self.lstm = nn.LSTM(u_dim + pb_dim, hidden, batch_first=True)
        self.dec = nn.Linear(hidden, y_dim)
        self.pb = nn.Parameter(torch.zeros(states, pb_dim))

    def forward(self, x0, u, state):
        # x0 (B, x), u (B, N, u), state (B,) -> y_hat (B, N, y)
        p = self.pb[state]
        h0 = torch.relu(self.enc_bn(self.enc(torch.cat((x0, p), dim=1))))
        steps = u.shape[1]
        lstm_in = torch.cat((u, p.unsqueeze(1).expand(-1, steps, -1)), dim=2)
        h0 = h0.unsqueeze(0)
        out, _ = self.lstm(lstm_in, (h0, torch.zeros_like(h0)))
        return self.dec(out)


# ----------------------------------------------------------------------------
# Training


def batches(perm, batch):
    out = [perm[b:b + batch] for b in range(0, perm.numel(), batch)]
    if out and out[-1].numel() < 2:
        out.pop()  # BatchNorm needs 2 windows
    return out


def train_step(model, opt, loss_fn, X, U, Y, S, idx):
    xb = X.index_select(0, idx)
    ub = U.index_select(0, idx)
    yb = Y.index_select(0, idx)
    sb = S.index_select(0, idx)
    loss = loss_fn(model(xb, ub, sb), yb)
    opt.zero_grad(set_to_none=True)
    loss.backward()
    opt.step()
    return loss.item()


def main(argv=None):
    ap = argparse.ArgumentParser(
        description="PyTorch baseline of the HADYNET C++ trainer: trains the same "
        "network on the same logs and reports seconds per training epoch.")
    ap.add_argument("--data", default="data/paper", help="dataset folder with manifest.json (default data/paper)")
    ap.add_argument("--epochs", type=int, default=3, help="training epochs (default 3)")
    ap.add_argument("--threads", type=int, default=2, help="torch.set_num_threads (default 2)")
    ap.add_argument("--batch", type=int, default=100, help="windows per batch (default 100)")
    ap.add_argument("--window", type=int, default=10, help="steps N per training window (default 10)")
    ap.add_argument("--hidden", type=int, default=128, help="LSTM units (default 128)")
    ap.add_argument("--pb-size", type=int, default=8, help="parametric-bias size (default 8)")
    ap.add_argument("--seed", type=int, default=1, help="seed of initialisation and shuffling (default 1)")
    ap.add_argument("--delta-groups", default="l,th",
                    help="comma-separated observed groups whose t minus t-1 difference is added to x (default l,th)")
    ap.add_argument("--json", metavar="OUT", help="write the results as JSON to OUT")
    args = ap.parse_args(argv)
    for name in ("epochs", "threads", "batch", "window", "hidden", "pb_size"):
        if getattr(args, name) < 1:
            ap.error(f"--{name} must be >= 1")
    if args.batch < 2:
        ap.error("--batch must be >= 2 (BatchNorm needs 2 windows)")

    torch.set_num_threads(args.threads)
    torch.autograd.set_detect_anomaly(False)
    torch.set_default_dtype(torch.float32)
    torch.manual_seed(args.seed)

    # Data loading and standardisation (not timed).
    delta_groups = {g for g in args.delta_groups.split(",") if g}
    t0 = time.perf_counter()
    x, u, y, s, states, n_logs = load_dataset(args.data, delta_groups, args.window)
    X = torch.from_numpy(standardise(x))
    U = torch.from_numpy(standardise(u)).contiguous()
    Y = torch.from_numpy(standardise(y)).contiguous()
    S = torch.from_numpy(s)
    load_s = time.perf_counter() - t0
    windows = X.shape[0]
    print(f"data: {args.data}: {n_logs} train logs, {len(states)} states, {windows} windows; "
          f"x {X.shape[1]}, u {U.shape[2]}, y {Y.shape[2]}, N {args.window} (loaded in {load_s:.2f} s)")

    model = Hadynet(X.shape[1], U.shape[2], Y.shape[2], len(states), args.pb_size, args.hidden)
    model.train()
    loss_fn = nn.MSELoss()

    # Untimed warm-up batch, then back to the initial model and a fresh optimiser.
    initial = copy.deepcopy(model.state_dict())
    warm_opt = torch.optim.Adam(model.parameters(), lr=1e-3)
    train_step(model, warm_opt, loss_fn, X, U, Y, S, torch.arange(min(args.batch, windows)))
    model.load_state_dict(initial)
    del warm_opt
    opt = torch.optim.Adam(model.parameters(), lr=1e-3)

    gen = torch.Generator()
    gen.manual_seed(args.seed)
    threads = torch.get_num_threads()
    blas = loaded_blas()
    load1 = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"torch {torch.__version__}, {threads} threads, batch {args.batch}, hidden {args.hidden}, pb {args.pb_size}")
    print(f"BLAS: {blas}; {os.cpu_count()} CPUs, load average {load1:.2f} before timing")
    if is_reference_blas(blas):
        print("warning: torch uses the reference (unoptimised) BLAS; install libopenblas0 for a fair baseline",
              file=sys.stderr)

    epoch_seconds, epoch_losses = [], []
    n_batches = 0
    for epoch in range(1, args.epochs + 1):
        perm = torch.randperm(windows, generator=gen)
        start = time.perf_counter()
        total = 0.0
        bl = batches(perm, args.batch)
        for idx in bl:
            total += train_step(model, opt, loss_fn, X, U, Y, S, idx)
        seconds = time.perf_counter() - start
        n_batches = len(bl)
        loss = total / n_batches
        epoch_seconds.append(seconds)
        epoch_losses.append(loss)
        print(f"epoch {epoch}  loss {loss:.6f}  {seconds:.3f} s  ({n_batches} batches)", flush=True)

    median = statistics.median(epoch_seconds)
    print(f"median seconds per epoch: {median:.3f}")

    if args.json:
        result = {
            "framework": "pytorch",
            "torch_version": torch.__version__,
            "threads": threads,
            "windows": windows,
            "batches_per_epoch": n_batches,
            "epoch_seconds": epoch_seconds,
            "median_epoch_seconds": median,
            "final_loss": epoch_losses[-1],
            "epoch_losses": epoch_losses,
            "blas": blas,
            "cpus": os.cpu_count(),
            "loadavg_1min_before": load1,
        }
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(result, f, indent=2)
            f.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
