"""Train, fine-tune and export a tactile hardness model (see models/README.md).

    python train.py --model small --train DATA/train --heldout DATA/heldout --out runs/small
    python train.py --model resnet50_lstm3 --init runs/r50-pretrain/model.pt --train REAL ...
    python train.py --model small --stream 1000 --heldout DATA/heldout --out runs/streamed

With --stream N the training presses are not read from disk: the `tactex` Python package
(`pip install ./python`) draws N fresh presses for every epoch as training consumes them
(epoch e is the data set of seed --stream-seed + e), and a validation set of --val-count
presses from a seed no epoch uses.

Writes to --out: model.pt (weights and recipe), model.onnx with model.json (what the Rust
`OnnxEstimator` reads), metrics.json (held-out scores) and predictions.jsonl.
"""

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from scipy import stats
from tqdm import tqdm

import architectures as arch
from shore import modulus_to_shore_a
from tactile_data import FRAME_PICKS, DrawnPresses, PressDataset, StreamedPresses, augment

FORMAT = "tactex-hardness-model/1"


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--model", required=True, choices=arch.MODELS)
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--train", nargs="+", help="datagen directories to train on")
    source.add_argument("--stream", type=int, metavar="N", help="train on N fresh presses per epoch drawn by the tactex package")
    p.add_argument("--stream-seed", type=int, default=0, help="epoch e of --stream draws the data set of this seed + e")
    p.add_argument("--val-count", type=int, default=200, help="validation presses drawn for --stream")
    p.add_argument("--sensor", default=None, help="sensor profile --stream draws around (default the built-in GelSight Mini)")
    p.add_argument("--workers", type=int, default=0, help="DataLoader worker processes drawing --stream presses")
    p.add_argument("--families", default=None, help="comma-separated shape families to train on")
    p.add_argument("--heldout", nargs="*", default=[], help="datagen directories of unseen shapes to score")
    p.add_argument("--out", required=True)
    p.add_argument("--frames", type=int, default=2, choices=[2, 4], help="difference frames read")
    p.add_argument("--epochs", type=int, default=30)
    p.add_argument("--batch", type=int, default=8)
    p.add_argument("--lr-early", type=float, default=5e-5, help="learning rate of the image encoder")
    p.add_argument("--lr-late", type=float, default=1e-3, help="learning rate of the sequence model and head")
    p.add_argument("--weight-decay", type=float, default=1e-4)
    p.add_argument("--dropout", type=float, default=0.1)
    p.add_argument(
        "--collapse-weight",
        type=float,
        default=4.0 / 25.0**2,
        help="weight of min(1/(Var(p)+1e-6), 1000); the paper's 4 on Shore values (sd ~25) is 4/25^2 on the standardised targets used here",
    )
    p.add_argument("--val-fraction", type=float, default=0.1)
    p.add_argument("--limit", type=int, default=None, help="at most this many training samples")
    p.add_argument("--init", default=None, help="model.pt to fine-tune from (pretrain, then fine-tune)")
    p.add_argument("--imagenet", action="store_true", help="start the backbone from torchvision's ImageNet weights")
    p.add_argument("--threads", type=int, default=os.cpu_count())
    p.add_argument("--seed", type=int, default=0)
    return p.parse_args()


def collapse_penalty(pred, weight):
    """The paper's anti-collapse term: large when the batch's predictions stop varying."""
    if pred.numel() < 2:
        return pred.new_zeros(())
    return weight * torch.clamp(1.0 / (pred.var() + 1e-6), max=1000.0)


def predict(model, dataset, batch=16):
    model.eval()
    out = []
    with torch.no_grad():
        for i in range(0, len(dataset), batch):
            frames = torch.stack([dataset[j][0] for j in range(i, min(i + batch, len(dataset)))])
            out.append(model(frames).reshape(-1))
    return torch.cat(out).numpy().astype(np.float64)


def scores(dataset, ln_pred):
    ln_true = dataset.targets.numpy().astype(np.float64)
    shore_true = np.array([r["shore_a"] for r in dataset.records])
    shore_pred = np.array([modulus_to_shore_a(math.exp(v)) for v in ln_pred])
    resid = shore_pred - shore_true
    return {
        "n": len(dataset),
        "families": sorted({r["family"] for r in dataset.records}),
        "ln_modulus_rmse": float(np.sqrt(np.mean((ln_pred - ln_true) ** 2))),
        "ln_modulus_spearman": float(stats.spearmanr(ln_true, ln_pred).statistic),
        "shore_a_rmse": float(np.sqrt(np.mean(resid**2))),
        "shore_a_r2": float(1.0 - np.sum(resid**2) / np.sum((shore_true - shore_true.mean()) ** 2)),
        "shore_a_spearman": float(stats.spearmanr(shore_true, shore_pred).statistic),
    }


def export_onnx(model, path, frames, height, width):
    model.eval()
    dummy = torch.full((1, frames + 1, height, width, 3), 128.0)
    torch.onnx.export(
        model,
        (dummy,),
        str(path),
        input_names=["frames"],
        output_names=["ln_modulus_mpa"],
        dynamic_axes={"frames": {0: "batch"}, "ln_modulus_mpa": {0: "batch"}},
        opset_version=17,
        dynamo=False,
    )
    # The exported graph must compute what the PyTorch model does.
    import onnxruntime

    probe = torch.rand(3, frames + 1, height, width, 3) * 255.0
    with torch.no_grad():
        expected = model(probe).numpy()
    got = onnxruntime.InferenceSession(str(path)).run(None, {"frames": probe.numpy()})[0]
    err = float(np.max(np.abs(got - expected)))
    if err > 1e-3:
        raise SystemExit(f"{path}: ONNX output differs from PyTorch by {err}")
    return err


def write_atomic(path, text):
    tmp = Path(str(path) + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def training_sensor(dirs):
    """The sensor profile (name, sha256) the training sets were drawn around, from their
    dataset.json; one for all of them, or None for sets written before profiles."""
    seen = set()
    for d in dirs:
        info_path = Path(d) / "dataset.json"
        if not info_path.is_file():
            raise SystemExit(f"{d}: no dataset.json (not a `tactex datagen tactile` directory)")
        sensor = json.loads(info_path.read_text()).get("sensor")
        seen.add(json.dumps(sensor, sort_keys=True) if sensor else None)
    if len(seen) > 1:
        raise SystemExit("--train: the data sets were drawn around different sensor profiles; a model card names one")
    only = seen.pop()
    return json.loads(only) if only else None


def streamed_sensor(path):
    """The profile (name, sha256) a --stream run draws around, as datagen names it."""
    import tactex

    return tactex.Sensor(path).profile_id


def main():
    args = parse_args()
    # Before any loading: a mix of sensors fails first, and so does a missing onnxruntime,
    # which the export after training checks the graph with.
    sensor = streamed_sensor(args.sensor) if args.stream else training_sensor(args.train)
    import onnxruntime  # noqa: F401
    torch.manual_seed(args.seed)
    torch.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    families = set(args.families.split(",")) if args.families else None

    with tqdm(desc="loading", unit=" presses") as bar:
        heldout = [PressDataset([d], args.frames, None, None, bar) for d in args.heldout]
        if args.stream:
            # Validation presses from a seed no epoch draws (epochs use stream-seed + e).
            val_seed = args.stream_seed + 1_000_003
            val_set = DrawnPresses(args.val_count, val_seed, args.frames, families, args.sensor, bar)
            train_set = StreamedPresses(args.stream, args.stream_seed, args.frames, families, args.sensor)
            records, train_targets = val_set.records, val_set.targets
            n_train, n_val = args.stream, len(val_set)
        else:
            data = PressDataset(args.train, args.frames, families, args.limit, bar)
    gen = torch.Generator().manual_seed(args.seed)
    if not args.stream:
        order = torch.randperm(len(data), generator=gen).tolist()
        n_val = max(1, int(round(args.val_fraction * len(data))))
        val_idx, train_idx = order[:n_val], order[n_val:]
        train_set = torch.utils.data.Subset(data, train_idx)
        val_set = torch.utils.data.Subset(data, val_idx)
        val_set.targets = data.targets[val_idx]
        val_set.records = [data.records[i] for i in val_idx]
        records, train_targets, n_train = data.records, data.targets[train_idx], len(train_idx)
    height, width = (val_set.frames[0] if args.stream else data.frames[0]).shape[1:3]

    if args.init:
        ckpt = torch.load(args.init, map_location="cpu", weights_only=False)
        if ckpt["recipe"]["model"] != args.model or ckpt["recipe"]["frames"] != args.frames:
            raise SystemExit(f"--init {args.init}: a {ckpt['recipe']['model']} on {ckpt['recipe']['frames']} frames, not {args.model} on {args.frames}")
        mean, sd = ckpt["target_mean"], ckpt["target_sd"]
    else:
        # A streamed run standardises by its validation draw, from the same distribution.
        t = train_targets
        mean, sd = float(t.mean()), float(t.std())
    model = arch.HardnessModel(arch.build(args.model, args.frames, args.dropout), mean, sd, height, width)
    if args.init:
        model.load_state_dict(ckpt["state"])
    elif args.imagenet and args.model != "small":
        arch.load_imagenet(model.regressor, args.model)

    early = model.regressor.early_parameters()
    early_ids = {id(p) for p in early}
    late = [p for p in model.parameters() if id(p) not in early_ids]
    opt = torch.optim.AdamW(
        [{"params": early, "lr": args.lr_early}, {"params": late, "lr": args.lr_late}],
        weight_decay=args.weight_decay,
    )
    if args.stream:
        loader = torch.utils.data.DataLoader(
            train_set, batch_size=args.batch, drop_last=True, num_workers=args.workers
        )
    else:
        loader = torch.utils.data.DataLoader(
            train_set, batch_size=args.batch, shuffle=True, drop_last=True, generator=gen
        )
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=max(1, args.epochs * len(loader)))
    what = f"{n_train} fresh presses per epoch" if args.stream else f"{n_train} train"
    print(f"{args.model}: {arch.parameter_count(model):,} parameters, {what} / {n_val} validation presses")

    best, history = None, []
    started = time.time()
    for epoch in range(args.epochs):
        if args.stream:
            train_set.set_epoch(epoch)
        model.train()
        total, count = 0.0, 0
        for frames, target in tqdm(loader, desc=f"epoch {epoch + 1}/{args.epochs}", leave=False):
            frames = augment(frames, gen)
            z = (target - mean) / sd
            pred = model.standardised(frames).reshape(-1)
            loss = F.mse_loss(pred, z) + collapse_penalty(pred, args.collapse_weight)
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            total += loss.item() * len(target)
            count += len(target)
        val_pred = predict(model, val_set)
        val_rmse = float(np.sqrt(np.mean((val_pred - val_set.targets.numpy()) ** 2)))
        history.append({"epoch": epoch + 1, "train_loss": total / count, "val_ln_rmse": val_rmse})
        print(f"epoch {epoch + 1}: train loss {total / count:.4f}, validation ln-modulus RMSE {val_rmse:.3f}", flush=True)
        if best is None or val_rmse < best[0]:
            best = (val_rmse, {k: v.clone() for k, v in model.state_dict().items()}, epoch + 1)
    model.load_state_dict(best[1])
    minutes = (time.time() - started) / 60.0

    recipe = {
        "height": int(height),
        "width": int(width),
        "model": args.model,
        "frames": args.frames,
        "frame_picks": FRAME_PICKS[args.frames],
        "train": (
            [f"tactex.generate: {args.stream} presses per epoch, seeds {args.stream_seed}..{args.stream_seed + args.epochs - 1}"]
            if args.stream
            else [str(d) for d in args.train]
        ),
        "families": sorted({r["family"] for r in records}),
        "train_presses": n_train * args.epochs if args.stream else n_train,
        "validation_presses": n_val,
        "epochs": args.epochs,
        "best_epoch": best[2],
        "batch": args.batch,
        "lr_early": args.lr_early,
        "lr_late": args.lr_late,
        "weight_decay": args.weight_decay,
        "dropout": args.dropout,
        "collapse_weight": args.collapse_weight,
        "schedule": "cosine",
        "augment": "flips, per-channel gain +-10%, offset +-8/255",
        "init": args.init,
        "imagenet": args.imagenet,
        "seed": args.seed,
        "threads": args.threads,
        "train_minutes": round(minutes, 1),
        "parameters": arch.parameter_count(model),
    }
    torch.save({"state": model.state_dict(), "recipe": recipe, "target_mean": mean, "target_sd": sd, "history": history}, out / "model.pt")

    metrics = {"validation": scores(val_set, predict(model, val_set)), "heldout": []}
    lines = []
    for d, ds in zip(args.heldout, heldout):
        pred = predict(model, ds)
        metrics["heldout"].append({"data": str(d), **scores(ds, pred)})
        for r, p in zip(ds.records, pred):
            lines.append(json.dumps({"data": str(d), "index": r["index"], "family": r["family"], "true_ln_modulus": math.log(r["modulus_mpa"]), "pred_ln_modulus": float(p), "true_shore_a": r["shore_a"], "pred_shore_a": modulus_to_shore_a(math.exp(p))}))
    write_atomic(out / "predictions.jsonl", "".join(line + "\n" for line in lines))

    export_err = export_onnx(model, out / "model.onnx", args.frames, height, width)
    spec = {
        "format": FORMAT,
        "model": args.model,
        "input": "frames",
        "input_layout": "[batch, first contact frame then the picked frames, height, width, RGB], float 0..255",
        "output": "ln_modulus_mpa",
        "frame_picks": FRAME_PICKS[args.frames],
        "height": int(height),
        "width": int(width),
        # Uncertainty floor for the Rust estimator: the held-out spread, else the validation one.
        "ln_modulus_rmse": (metrics["heldout"][0] if metrics["heldout"] else metrics["validation"])["ln_modulus_rmse"],
        "onnx_vs_torch_max_abs": export_err,
        # The family of sensors whose frames it has seen; tactex says so on another's frames.
        **({"sensor": sensor} if sensor else {}),
        "recipe": recipe,
        "metrics": metrics,
    }
    write_atomic(out / "model.json", json.dumps(spec, indent=2) + "\n")
    write_atomic(out / "metrics.json", json.dumps(metrics, indent=2) + "\n")
    print(json.dumps(metrics, indent=2))


if __name__ == "__main__":
    sys.exit(main())
