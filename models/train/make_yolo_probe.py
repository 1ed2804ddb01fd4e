"""Writes the YOLOv8-seg probe models the Rust tests load: Ultralytics' real signature
(images [1, 3, 640, 640] -> output0 [1, 4 + classes + 32, 8400], output1 [1, 32, 160, 160])
with outputs the tests know exactly, so that they check the letterbox, decoding, NMS and
masks from prototypes against a drawn image:

* prototypes: a 4x4 average pool of the input, then 1x1 weights: channel 0 = 10 (R - G) - 2
  (positive on red, negative on grey and green), channel 1 = 10 (G - R) - 2, the rest 0;
* predictions: four anchors, zero-padded to 8400 (scores 0 are below any threshold):
  an apple box over a red disk at image (400, 200) r 40 with mask coefficients picking
  channel 0 (score 0.9), a shifted duplicate (0.6, removed by NMS), a lime box over a green
  disk at image (200, 300) r 30 picking channel 1 (0.8), and a banana at 0.1 (below 0.25).
  Image y maps to input y + 80 (a 640x480 frame letterboxed into 640x640).

    python make_yolo_probe.py OUT_DIR

writes yolo-seg-probe.onnx (class names in metadata as Ultralytics writes them),
yolo-seg-probe-unnamed.onnx (no names), yolo-seg-probe-two-names.onnx (names that do not
match the channels) and yolo-det-probe.onnx (a detection model: no prototypes).
"""

import sys
from pathlib import Path

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

NAMES = ["apple", "lime", "banana"]
K, ANCHORS, M = 4, 8400, 32


def predictions(nc):
    p = np.zeros((1, 4 + nc + M, K), np.float32)

    def anchor(a, cx, cy, w, h, cls, score, channel):
        p[0, 0:4, a] = [cx, cy, w, h]
        p[0, 4 + cls, a] = score
        if channel is not None:
            p[0, 4 + nc + channel, a] = 1.0

    anchor(0, 400, 280, 84, 84, 0, 0.9, 0)
    anchor(1, 403, 282, 84, 84, 0, 0.6, 0)
    anchor(2, 200, 380, 64, 64, 1, 0.8, 1)
    anchor(3, 100, 100, 20, 20, 2, 0.1, None)
    return p


def model(names, with_prototypes=True, nc=len(NAMES)):
    w = np.zeros((M, 3, 1, 1), np.float32)
    b = np.zeros((M,), np.float32)
    w[0, 0], w[0, 1], b[0] = 10, -10, -2
    w[1, 1], w[1, 0], b[1] = 10, -10, -2
    inits = [
        numpy_helper.from_array(predictions(nc), "anchors"),
        numpy_helper.from_array(np.array([0, 0, 0, 0, 0, ANCHORS - K], np.int64), "pads"),
        numpy_helper.from_array(np.array(0.0, np.float32), "zero"),
        numpy_helper.from_array(w, "proto_w"),
        numpy_helper.from_array(b, "proto_b"),
        numpy_helper.from_array(np.array(0.0, np.float32), "nothing"),
    ]
    nodes = [
        # The constant predictions, made to depend on the input (times zero) as a real model's.
        helper.make_node("ReduceMean", ["images"], ["mean"], keepdims=0),
        helper.make_node("Mul", ["mean", "nothing"], ["no_change"]),
        helper.make_node("Pad", ["anchors", "pads", "zero"], ["padded"], mode="constant"),
        helper.make_node("Add", ["padded", "no_change"], ["output0"]),
        helper.make_node("AveragePool", ["images"], ["pooled"], kernel_shape=[4, 4], strides=[4, 4]),
        helper.make_node("Conv", ["pooled", "proto_w", "proto_b"], ["output1"]),
    ]
    outputs = [helper.make_tensor_value_info("output0", TensorProto.FLOAT, [1, 4 + nc + M, ANCHORS])]
    if with_prototypes:
        outputs.append(helper.make_tensor_value_info("output1", TensorProto.FLOAT, [1, M, 160, 160]))
    else:
        nodes = nodes[:4]
        inits = inits[:3] + inits[5:]
    graph = helper.make_graph(
        nodes,
        "yolo_seg_probe",
        [helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, 640, 640])],
        outputs,
        inits,
    )
    m = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)], producer_name="tactex make_yolo_probe.py")
    m.ir_version = 8
    if names is not None:
        literal = "{" + ", ".join(f"{i}: '{n}'" for i, n in enumerate(names)) + "}"
        helper.set_model_props(m, {"task": "segment", "names": literal, "imgsz": "[640, 640]"})
    onnx.checker.check_model(m)
    return m


def main(out):
    out = Path(out)
    onnx.save(model(NAMES), out / "yolo-seg-probe.onnx")
    onnx.save(model(None), out / "yolo-seg-probe-unnamed.onnx")
    onnx.save(model(NAMES[:2]), out / "yolo-seg-probe-two-names.onnx")
    onnx.save(model(NAMES, with_prototypes=False), out / "yolo-det-probe.onnx")


if __name__ == "__main__":
    main(sys.argv[1])
