"""Writes the probe model the Rust tests load: the hardness model's real input and output
(frames [B, 3, 240, 320, 3] -> ln_modulus_mpa [B, 1]) with an output the tests can compute by
hand from the frames, so that they check frame picking, layout and batching exactly:

    ln_modulus_mpa = C0 + C1 * (mean(frame 2) - mean(frame 0)) + C2 * mean(frame 1) + C3 * mean(red of frame 2)

Every term is a mean over the image, so flips leave it unchanged.

    python make_probe_model.py OUT.onnx   (also writes OUT.json)
"""

import json
import sys
from pathlib import Path

import onnx
from onnx import TensorProto, helper

C0, C1, C2, C3 = -1.0, 0.02, 0.001, 0.005


def main(out):
    out = Path(out)
    const = lambda name, v: helper.make_tensor(name, TensorProto.FLOAT, [], [v])
    index = lambda name, v: helper.make_tensor(name, TensorProto.INT64, [], [v])
    nodes, inits = [], [const("c0", C0), const("c1", C1), const("c2", C2), const("c3", C3)]
    for k in range(3):
        inits.append(index(f"i{k}", k))
        nodes.append(helper.make_node("Gather", ["frames", f"i{k}"], [f"g{k}"], axis=1))
        nodes.append(helper.make_node("ReduceMean", [f"g{k}"], [f"m{k}"], axes=[1, 2, 3], keepdims=0))
    inits += [index("red", 0), helper.make_tensor("axis1", TensorProto.INT64, [1], [1])]
    nodes += [
        helper.make_node("Gather", ["g2", "red"], ["r2"], axis=3),
        helper.make_node("ReduceMean", ["r2"], ["mr2"], axes=[1, 2], keepdims=0),
        helper.make_node("Sub", ["m2", "m0"], ["d20"]),
        helper.make_node("Mul", ["d20", "c1"], ["t1"]),
        helper.make_node("Mul", ["m1", "c2"], ["t2"]),
        helper.make_node("Mul", ["mr2", "c3"], ["t3"]),
        helper.make_node("Add", ["t1", "t2"], ["s12"]),
        helper.make_node("Add", ["s12", "t3"], ["s123"]),
        helper.make_node("Add", ["s123", "c0"], ["flat"]),
        helper.make_node("Unsqueeze", ["flat", "axis1"], ["ln_modulus_mpa"]),
    ]
    graph = helper.make_graph(
        nodes,
        "hardness_probe",
        [helper.make_tensor_value_info("frames", TensorProto.FLOAT, ["batch", 3, 240, 320, 3])],
        [helper.make_tensor_value_info("ln_modulus_mpa", TensorProto.FLOAT, ["batch", 1])],
        inits,
    )
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)], producer_name="tactex make_probe_model.py")
    model.ir_version = 8
    onnx.checker.check_model(model)
    onnx.save(model, out)
    spec = {
        "format": "tactex-hardness-model/1",
        "model": "probe",
        "input": "frames",
        "output": "ln_modulus_mpa",
        "frame_picks": [0, 1, 7],
        "height": 240,
        "width": 320,
        "ln_modulus_rmse": 0.25,
        "probe_coefficients": [C0, C1, C2, C3],
    }
    out.with_suffix(".json").write_text(json.dumps(spec, indent=2) + "\n")


if __name__ == "__main__":
    main(sys.argv[1])
