"""Batched image augmentation for Chapter 6 (thesis Fig. 6.7: flip, brightness, zoom), plain torch.

Each transform acts on a whole batch ``(N, H, W, 3)`` of float images in [0, 255] on the
training device, with per-sample random parameters drawn from a seeded ``torch.Generator``:

* horizontal flip with probability ``flip_prob`` — the steering label is negated (a mirrored road
  bends the other way); throttle and speed are unchanged;
* brightness: multiply by a factor in ``brightness`` (clipped to [0, 255]);
* zoom: scale about the image centre by a factor in ``zoom`` (bilinear ``grid_sample``).

Plain torch rather than kornia: three transforms are a few lines each, run in the same batched
way, and avoid a second library's random-state handling (kornia stays in the ``learning`` extra
for users who want more transforms).
"""

from __future__ import annotations

from typing import Any


def augment_batch(
    images: Any,
    steering: Any,
    generator: Any,
    *,
    flip_prob: float = 0.5,
    brightness: tuple[float, float] = (0.6, 1.3),
    zoom: tuple[float, float] = (1.0, 1.3),
) -> tuple[Any, Any]:
    """Augment a batch.

    Args:
        images: ``(N, H, W, 3)`` float tensor in [0, 255].
        steering: ``(N,)`` steering labels.
        generator: ``torch.Generator`` (on the images' device).
        flip_prob: probability of a horizontal flip per sample.
        brightness: range of the multiplicative brightness factor.
        zoom: range of the zoom factor (≥ 1 zooms in).

    Returns:
        ``(images, steering)`` augmented (new tensors).
    """
    import torch
    from torch.nn import functional

    n = images.shape[0]
    dev = images.device
    x = images.float().clone()  # never modify the caller's batch
    s = steering.clone().float()
    flip = torch.rand(n, generator=generator, device=dev) < flip_prob
    if flip.any():
        x[flip] = torch.flip(x[flip], dims=[2])
        s[flip] = -s[flip]
    lo, hi = brightness
    b = lo + (hi - lo) * torch.rand(n, generator=generator, device=dev)
    x = (x * b[:, None, None, None]).clamp(0.0, 255.0)
    zlo, zhi = zoom
    if zhi > 1.0 or zlo < 1.0:
        z = zlo + (zhi - zlo) * torch.rand(n, generator=generator, device=dev)
        theta = torch.zeros(n, 2, 3, device=dev)
        theta[:, 0, 0] = 1.0 / z
        theta[:, 1, 1] = 1.0 / z
        chw = x.permute(0, 3, 1, 2)
        grid = functional.affine_grid(theta, list(chw.shape), align_corners=False)
        chw = functional.grid_sample(
            chw, grid, mode="bilinear", padding_mode="border", align_corners=False
        )
        x = chw.permute(0, 2, 3, 1).contiguous()
    return x, s
