"""Re-export a trained checkpoint to ONNX (checked against onnxruntime) and refresh its card.

    python export.py runs/small/model.pt OUT.onnx   (writes OUT.json from the run's model.json)
"""

import json
import sys
from pathlib import Path

import torch

import architectures as arch
from train import export_onnx, write_atomic


def main(checkpoint, out):
    ckpt = torch.load(checkpoint, map_location="cpu", weights_only=False)
    recipe = ckpt["recipe"]
    height, width = recipe.get("height", 240), recipe.get("width", 320)
    model = arch.HardnessModel(arch.build(recipe["model"], recipe["frames"], recipe["dropout"]), ckpt["target_mean"], ckpt["target_sd"], height, width)
    model.load_state_dict(ckpt["state"])
    out = Path(out)
    err = export_onnx(model, out, recipe["frames"], height, width)
    card = json.loads((Path(checkpoint).parent / "model.json").read_text())
    card["onnx_vs_torch_max_abs"] = err
    write_atomic(out.with_suffix(".json"), json.dumps(card, indent=2) + "\n")
    print(f"{out}: ONNX matches PyTorch to {err:.1e}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
