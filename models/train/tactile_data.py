"""Press sequences written by `tactex datagen tactile`, or drawn on the fly by the `tactex`
Python package, as training tensors.

A sample is the first contact frame followed by the frames the model reads (DESIGN.md stage 4:
frames 2 and 8, or 2, 4, 6 and 8, counted from 1 at first contact), raw RGB in 0..255 and
channels last, exactly what the Rust `OnnxEstimator` feeds the exported graph. Differences and
resizing happen inside the model so that Python and Rust cannot disagree on preprocessing.
"""

import json
import math
from pathlib import Path

import numpy as np
import torch
from PIL import Image

# Frame picks, as 0-based indices into the 8 press frames (0 = first contact frame).
FRAME_PICKS = {2: [0, 1, 7], 4: [0, 1, 3, 5, 7]}


def read_manifest(root):
    """All manifest lines of a data set directory (every shard), in index order."""
    root = Path(root)
    info_path = root / "dataset.json"
    if not info_path.is_file():
        raise SystemExit(f"{root}: no dataset.json (not a `tactex datagen tactile` directory)")
    lines = []
    for shard in sorted(root.glob("shard-*-of-*.jsonl")):
        with open(shard) as f:
            for n, line in enumerate(f, 1):
                if not line.endswith("\n"):
                    break  # an interrupted writer's last line
                try:
                    lines.append(json.loads(line))
                except json.JSONDecodeError as e:
                    raise SystemExit(f"{shard}:{n}: not JSON ({e})")
    if not lines:
        raise SystemExit(f"{root}: no samples in its shard manifests")
    return sorted(lines, key=lambda r: r["index"])


def load_frames(root, record, picks):
    """uint8 [len(picks), H, W, 3] of the picked press frames (reference not included)."""
    files = record["files"]
    if len(files) == 1 and files[0].endswith(".npz"):
        with np.load(Path(root) / files[0]) as npz:
            frames = npz["frames"]  # [9, H, W, 3], reference first
        return np.stack([frames[1 + k] for k in picks])
    by_name = {Path(f).name: f for f in files}
    return np.stack(
        [np.asarray(Image.open(Path(root) / by_name[f"frame_{k}.png"]).convert("RGB")) for k in picks]
    )


def ln_modulus(record):
    return math.log(record["modulus_mpa"])


class PressDataset(torch.utils.data.Dataset):
    """Samples held in memory as uint8 (about 0.7 MB each with 3 frames)."""

    def __init__(self, roots, frames=2, families=None, limit=None, progress=None):
        picks = FRAME_PICKS[frames]
        self.records, self.frames = [], []
        for root in roots:
            for record in read_manifest(root):
                if families and record["family"] not in families:
                    continue
                if limit is not None and len(self.records) >= limit:
                    break
                self.records.append(record)
                self.frames.append(load_frames(root, record, picks))
                if progress is not None:
                    progress.update(1)
        if not self.records:
            raise SystemExit(f"{', '.join(map(str, roots))}: no samples of families {families}")
        self.targets = torch.tensor([ln_modulus(r) for r in self.records], dtype=torch.float32)

    def __len__(self):
        return len(self.records)

    def __getitem__(self, i):
        return torch.from_numpy(self.frames[i]).float(), self.targets[i]


class StreamedPresses(torch.utils.data.IterableDataset):
    """Fresh presses drawn by the twin as training consumes them (`tactex.generate`, the
    Python package): `count` per epoch, epoch e drawing the data set of seed `seed + e`, so
    that no press is seen twice. Each DataLoader worker draws its own share of the indices
    (`tactex.worker_shard`), so N workers yield each press of an epoch exactly once."""

    def __init__(self, count, seed, frames=2, families=None, sensor=None):
        import tactex

        self.tactex = tactex
        self.count, self.seed, self.picks = count, seed, FRAME_PICKS[frames]
        self.families = sorted(families) if families else None
        self.sensor = sensor
        self.epoch = 0

    def __len__(self):
        return self.count

    def set_epoch(self, epoch):
        self.epoch = epoch

    def __iter__(self):
        info = torch.utils.data.get_worker_info()
        shard = (0, 1) if info is None else self.tactex.worker_shard((0, 1), info.id, info.num_workers)
        for s in self.tactex.generate(
            self.count, self.seed + self.epoch, shard=shard, shapes=self.families, sensor=self.sensor
        ):
            picked = np.stack([s.frames[1 + k] for k in self.picks])
            yield torch.from_numpy(picked).float(), torch.tensor(ln_modulus(s.labels), dtype=torch.float32)


class DrawnPresses(torch.utils.data.Dataset):
    """A fixed set of presses drawn by the twin in memory (`tactex.generate`): the
    validation set of a streamed run, with the records a folder's manifest would hold."""

    def __init__(self, count, seed, frames=2, families=None, sensor=None, progress=None):
        import tactex

        picks = FRAME_PICKS[frames]
        self.records, self.frames = [], []
        for s in tactex.generate(count, seed, shapes=sorted(families) if families else None, sensor=sensor):
            self.records.append(s.labels)
            self.frames.append(np.stack([s.frames[1 + k] for k in picks]))
            if progress is not None:
                progress.update(1)
        self.targets = torch.tensor([ln_modulus(r) for r in self.records], dtype=torch.float32)

    def __len__(self):
        return len(self.records)

    def __getitem__(self, i):
        return torch.from_numpy(self.frames[i]).float(), self.targets[i]


def augment(frames, generator):
    """The paper's flips and colour jitter on a batch [B, F, H, W, 3] (0..255), one draw per
    sequence so that all its frames change alike."""
    b = frames.shape[0]
    out = frames.clone()
    for i in range(b):
        if torch.rand((), generator=generator) < 0.5:
            out[i] = out[i].flip(2)  # left-right
        if torch.rand((), generator=generator) < 0.5:
            out[i] = out[i].flip(1)  # up-down
    gain = 1.0 + 0.1 * (2 * torch.rand(b, 1, 1, 1, 3, generator=generator) - 1)
    offset = 8.0 * (2 * torch.rand(b, 1, 1, 1, 1, generator=generator) - 1)
    return (out * gain + offset).clamp(0.0, 255.0)
