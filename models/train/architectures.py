"""The hardness regressors: the paper's three (Table I) and a small CPU model.

Every model takes raw frames [B, F, H, W, 3] in 0..255 (first contact frame, then the frames it
reads) and returns ln(E / MPa) [B, 1]. `PressInput` forms the paper's input: each later frame
minus the first contact frame, scaled to [-1, 1] and resized to 224 x 224.
"""

import torch
import torch.nn as nn
import torch.nn.functional as F
import torchvision

SIDE = 224


def bilinear_matrix(n_in, n_out):
    """[n_out, n_in]: F.interpolate's bilinear resize (align_corners=False) along one axis, as a
    matrix, so the exported graph resizes by MatMul (which every ONNX runtime runs, tract's
    Resize included or not)."""
    eye = torch.eye(n_in).reshape(1, 1, n_in, n_in)
    return F.interpolate(eye, size=(n_out, n_in), mode="bilinear", align_corners=False)[0, 0]


class PressInput(nn.Module):
    """[B, F, H, W, 3] raw frames -> [B, F-1, 3, 224, 224] differences to the first frame."""

    def __init__(self, height=240, width=320):
        super().__init__()
        self.register_buffer("rows", bilinear_matrix(height, SIDE), persistent=False)
        self.register_buffer("cols", bilinear_matrix(width, SIDE).t().contiguous(), persistent=False)

    def forward(self, frames):
        b, f, h, w, c = frames.shape
        diff = (frames[:, 1:] - frames[:, :1]) / 255.0
        diff = diff.permute(0, 1, 4, 2, 3)  # [B, F-1, 3, H, W]
        return torch.matmul(torch.matmul(self.rows, diff), self.cols)


def conv_block(cin, cout, kernel, stride):
    return nn.Sequential(
        nn.Conv2d(cin, cout, kernel, stride, kernel // 2, bias=False),
        nn.BatchNorm2d(cout),
        nn.ReLU(inplace=True),
    )


class SmallPressNet(nn.Module):
    """The CPU model: the difference frames stacked as channels, five strided convolutions,
    average and max pooling (how much the gel moved, and where it moved most), and an MLP."""

    def __init__(self, diffs, dropout=0.1):
        super().__init__()
        self.features = nn.Sequential(
            conv_block(3 * diffs, 24, 5, 2),  # 112
            conv_block(24, 32, 3, 2),  # 56
            conv_block(32, 48, 3, 2),  # 28
            conv_block(48, 64, 3, 2),  # 14
            conv_block(64, 96, 3, 2),  # 7
        )
        self.head = nn.Sequential(
            nn.Linear(2 * 96, 64), nn.ReLU(inplace=True), nn.Dropout(dropout), nn.Linear(64, 1)
        )

    def forward(self, x):
        b, d, c, h, w = x.shape
        y = self.features(x.reshape(b, d * c, h, w))
        pooled = torch.cat([y.mean(dim=(2, 3)), y.amax(dim=(2, 3))], dim=1)
        return self.head(pooled)

    def early_parameters(self):
        return list(self.features.parameters())


class FrameEncoderSequence(nn.Module):
    """A per-frame image encoder followed by a model of the frame sequence."""

    def __init__(self, encoder, width, temporal, dropout):
        super().__init__()
        self.encoder = encoder
        self.temporal_kind = temporal
        if temporal == "lstm1":
            self.temporal = nn.LSTM(width, 256, num_layers=1, batch_first=True)
            out = 256
        elif temporal == "lstm3":
            self.temporal = nn.LSTM(width, 256, num_layers=3, batch_first=True, dropout=dropout)
            out = 256
        elif temporal == "transformer":
            layer = nn.TransformerEncoderLayer(
                width, nhead=8, dim_feedforward=2 * width, dropout=dropout, batch_first=True
            )
            self.temporal = nn.TransformerEncoder(layer, num_layers=2, enable_nested_tensor=False)
            self.position = nn.Parameter(torch.zeros(1, 8, width))
            out = width
        else:
            raise ValueError(temporal)
        self.head = nn.Sequential(nn.Dropout(dropout), nn.Linear(out, 64), nn.ReLU(), nn.Linear(64, 1))

    def forward(self, x):
        b, d, c, h, w = x.shape
        feats = self.encoder(x.reshape(b * d, c, h, w)).reshape(b, d, -1)
        if self.temporal_kind == "transformer":
            seq = self.temporal(feats + self.position[:, :d])
            last = seq.mean(dim=1)
        else:
            seq, _ = self.temporal(feats)
            last = seq[:, -1]
        return self.head(last)

    def early_parameters(self):
        return list(self.encoder.parameters())


def vgg16_encoder():
    vgg = torchvision.models.vgg16(weights=None)
    return nn.Sequential(vgg.features, nn.AdaptiveAvgPool2d(1), nn.Flatten()), 512


def resnet50_encoder():
    net = torchvision.models.resnet50(weights=None)
    net.fc = nn.Identity()
    return net, 2048


def convnext_encoder():
    net = torchvision.models.convnext_tiny(weights=None)
    net.classifier = nn.Sequential(net.classifier[0], net.classifier[1])  # LayerNorm, Flatten
    return net, 768


def build(name, diffs, dropout):
    if name == "small":
        return SmallPressNet(diffs, dropout)
    if name == "vgg16_lstm":
        enc, width = vgg16_encoder()
        return FrameEncoderSequence(enc, width, "lstm1", dropout)
    if name == "resnet50_lstm3":
        enc, width = resnet50_encoder()
        return FrameEncoderSequence(enc, width, "lstm3", dropout)
    if name == "convnext_transformer":
        enc, width = convnext_encoder()
        return FrameEncoderSequence(enc, width, "transformer", dropout)
    raise SystemExit(f"--model: unknown '{name}' (small, vgg16_lstm, resnet50_lstm3, convnext_transformer)")


MODELS = ["small", "vgg16_lstm", "resnet50_lstm3", "convnext_transformer"]

# torchvision's ImageNet weights for each backbone, used with --imagenet where they can be fetched.
IMAGENET = {
    "vgg16_lstm": ("vgg16", "VGG16_Weights"),
    "resnet50_lstm3": ("resnet50", "ResNet50_Weights"),
    "convnext_transformer": ("convnext_tiny", "ConvNeXt_Tiny_Weights"),
}


def load_imagenet(model, name):
    arch, weights = IMAGENET[name]
    state = getattr(torchvision.models, weights).IMAGENET1K_V1.get_state_dict(progress=True)
    reference = getattr(torchvision.models, arch)(weights=None)
    reference.load_state_dict(state)
    encoder = model.encoder
    source = reference.features if name == "vgg16_lstm" else reference
    target = encoder[0] if name == "vgg16_lstm" else encoder
    missing, _ = target.load_state_dict(source.state_dict(), strict=False)
    return missing


class HardnessModel(nn.Module):
    """Raw frames in, ln(E / MPa) out: the exported graph. The regressor works on standardised
    targets; the training set's mean and spread are kept as buffers."""

    def __init__(self, regressor, target_mean=0.0, target_sd=1.0, height=240, width=320):
        super().__init__()
        self.input = PressInput(height, width)
        self.regressor = regressor
        self.register_buffer("target_mean", torch.tensor(float(target_mean)))
        self.register_buffer("target_sd", torch.tensor(float(target_sd)))

    def standardised(self, frames):
        return self.regressor(self.input(frames))

    def forward(self, frames):
        return self.standardised(frames) * self.target_sd + self.target_mean


def parameter_count(model):
    return sum(p.numel() for p in model.parameters())
