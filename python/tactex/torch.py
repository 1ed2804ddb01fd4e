"""PyTorch data sets over the twin's tactile samples (torch is imported only here).

``TactileStream`` draws samples on the fly (``tactex.generate``), each DataLoader worker its
own share of the indices, so that N workers yield every sample exactly once;
``TactileFolder`` reads a data set ``tactex datagen tactile`` wrote (PNG or NPZ).

A sample is ``(frames, target)``: frames a uint8 tensor (9, H, W, 3), the no-contact
reference first; target the label named by ``target`` (default ``ln(modulus_mpa)``, the
quantity the project's models regress).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np
import torch
from torch.utils.data import Dataset, IterableDataset, get_worker_info

from . import Sample, generate, shard_indices, worker_shard
from .errors import MissingFile

Target = Callable[[Dict[str, Any]], float]


def ln_modulus(labels: Dict[str, Any]) -> float:
    """ln(E / MPa) of the pressed object."""
    return math.log(float(labels["modulus_mpa"]))


class TactileStream(IterableDataset):
    """Samples 0 .. ``count`` - 1 of shard ``shard`` of the data set ``datagen tactile
    --count COUNT --seed SEED ...`` would write, drawn in memory as they are consumed. With
    a DataLoader of N workers, worker k draws every N-th of them, so that each sample comes
    exactly once."""

    def __init__(
        self,
        count: int,
        seed: int = 0,
        *,
        shard: Tuple[int, int] = (0, 1),
        fidelity: str = "layer",
        shapes: Optional[Sequence[str]] = None,
        sensor: Optional[Union[str, "os.PathLike[str]"]] = None,
        target: Target = ln_modulus,
        batch: Optional[int] = None,
    ) -> None:
        super().__init__()
        shard_indices(count, shard)  # checks the arguments now, not in a worker
        self.count, self.seed, self.shard = count, seed, shard
        self.fidelity, self.shapes, self.sensor = fidelity, shapes, sensor
        self.target, self.batch = target, batch

    def __len__(self) -> int:
        return len(shard_indices(self.count, self.shard))

    def _worker_shard(self) -> Tuple[int, int]:
        info = get_worker_info()
        if info is None:
            return self.shard
        return worker_shard(self.shard, info.id, info.num_workers)

    def samples(self, shard: Optional[Tuple[int, int]] = None) -> Iterator[Sample]:
        """The samples of ``shard`` (default this worker's), as ``tactex.Sample``."""
        return generate(
            self.count,
            self.seed,
            shard=shard or self._worker_shard(),
            fidelity=self.fidelity,
            shapes=self.shapes,
            sensor=self.sensor,
            batch=self.batch,
        )

    def __iter__(self) -> Iterator[Tuple[torch.Tensor, torch.Tensor]]:
        for s in self.samples():
            yield torch.from_numpy(s.frames), torch.tensor(self.target(s.labels))


class TactileFolder(Dataset):
    """A data set ``tactex datagen tactile`` wrote to ``root`` (every shard's manifest; PNG
    or NPZ samples), indexed by position in ascending sample index."""

    def __init__(self, root: Union[str, "os.PathLike[str]"], target: Target = ln_modulus) -> None:
        self.root = Path(root)
        info_path = self.root / "dataset.json"
        try:
            self.info: Dict[str, Any] = json.loads(info_path.read_text())
        except FileNotFoundError:
            raise MissingFile(f"{info_path}: not a tactex data set (no dataset.json)") from None
        lines: List[Dict[str, Any]] = []
        for manifest in sorted(self.root.glob("shard-*-of-*.jsonl")):
            with open(manifest) as f:
                lines += [json.loads(line) for line in f if line.endswith("\n")]
        self.lines = sorted(lines, key=lambda line: line["index"])
        self.target = target

    def __len__(self) -> int:
        return len(self.lines)

    def frames(self, k: int) -> np.ndarray:
        """Sample k's frames (9, H, W, 3) uint8, the reference first."""
        files = self.lines[k]["files"]
        if len(files) == 1 and files[0].endswith(".npz"):
            with np.load(self.root / files[0]) as z:
                return z["frames"]
        from PIL import Image

        return np.stack([np.asarray(Image.open(self.root / f).convert("RGB")) for f in files])

    def __getitem__(self, k: int) -> Tuple[torch.Tensor, torch.Tensor]:
        return torch.from_numpy(self.frames(k)), torch.tensor(self.target(self.lines[k]))
