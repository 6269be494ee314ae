"""Figures of thesis Chapter 6 (Figs. 6.1, 6.4–6.8) and the ``drive play`` video.

* :func:`fig_camera_views` — left/centre/right forward images (Fig. 6.1);
* :func:`fig_steering_histogram` — steering distribution before (Fig. 6.4) or after balancing
  (Fig. 6.5), with the threshold line;
* :func:`fig_split` — training vs validation steering distribution (Fig. 6.6);
* :func:`fig_augmentation` — original vs flipped / brightness / zoom (Fig. 6.7);
* :func:`fig_loss` — training and validation MSE per epoch (Fig. 6.8);
* :func:`write_drive_video` — frames with predicted vs expert steering (GIF via Pillow, MP4 via
  matplotlib's ffmpeg writer when ffmpeg is installed).

Explicit Agg canvases, no ``pyplot`` (as :mod:`uvnav.viz.figures`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from uvnav.viz.figures import DPI, new_figure, save_figure


def fig_camera_views(
    views: Sequence[NDArray[np.uint8]],
    path: str | Path,
    *,
    titles: Sequence[str] = ("left", "center", "right"),
) -> Path:
    """Fig. 6.1: the three forward camera images side by side."""
    fig = new_figure(3.0 * len(views), 1.4)
    for k, (img, title) in enumerate(zip(views, titles, strict=False)):
        ax = fig.add_subplot(1, len(views), k + 1)
        ax.imshow(img)
        ax.set_title(title, fontsize=9)
        ax.axis("off")
    return save_figure(fig, path)


def fig_steering_histogram(
    steering: NDArray[np.float64],
    path: str | Path,
    *,
    n_bins: int = 25,
    threshold: int | None = 200,
    title: str = "steering angle distribution",
) -> Path:
    """Figs. 6.4/6.5: steering histogram over [-1, 1] with the balancing threshold."""
    fig = new_figure(5.0, 3.0)
    ax = fig.add_subplot(1, 1, 1)
    ax.hist(np.clip(steering, -1, 1), bins=n_bins, range=(-1, 1), color="tab:blue", alpha=0.85)
    if threshold:
        ax.axhline(threshold, color="tab:red", ls="--", lw=1, label=f"threshold {threshold}")
        ax.legend(fontsize=8)
    ax.set_xlabel("steering (normalised, + right)")
    ax.set_ylabel("samples")
    ax.set_title(
        f"{title} (n={len(steering)}, mean {np.mean(steering):.3f}, std {np.std(steering):.3f})",
        fontsize=9,
    )
    return save_figure(fig, path)


def fig_split(
    train: NDArray[np.float64], val: NDArray[np.float64], path: str | Path, *, n_bins: int = 25
) -> Path:
    """Fig. 6.6: steering distribution of the training and validation sets."""
    fig = new_figure(8.0, 3.0)
    for k, (vals, name, color) in enumerate(
        ((train, "training", "tab:blue"), (val, "validation", "tab:orange"))
    ):
        ax = fig.add_subplot(1, 2, k + 1)
        ax.hist(np.clip(vals, -1, 1), bins=n_bins, range=(-1, 1), color=color)
        ax.set_title(f"{name} set ({len(vals)} images)", fontsize=9)
        ax.set_xlabel("steering")
    return save_figure(fig, path)


def fig_augmentation(
    rows: Sequence[tuple[str, NDArray[np.uint8], NDArray[np.uint8], str]], path: str | Path
) -> Path:
    """Fig. 6.7: each row ``(name, original, augmented, caption)``."""
    fig = new_figure(7.0, 1.5 * len(rows))
    for k, (name, orig, aug, caption) in enumerate(rows):
        for j, (img, title) in enumerate(((orig, "original"), (aug, f"{name}: {caption}"))):
            ax = fig.add_subplot(len(rows), 2, 2 * k + j + 1)
            ax.imshow(np.asarray(img, dtype=np.uint8))
            ax.set_title(title, fontsize=8)
            ax.axis("off")
    return save_figure(fig, path)


def fig_loss(train_loss: Sequence[float], val_loss: Sequence[float], path: str | Path) -> Path:
    """Fig. 6.8: MSE (6.1) per epoch."""
    fig = new_figure(5.0, 3.0)
    ax = fig.add_subplot(1, 1, 1)
    ep = np.arange(1, len(train_loss) + 1)
    ax.plot(ep, train_loss, "o-", label="training")
    if len(val_loss):
        ax.plot(np.arange(1, len(val_loss) + 1), val_loss, "s-", label="validation")
    ax.set_xlabel("epoch")
    ax.set_ylabel("MSE")
    ax.set_yscale("log")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return save_figure(fig, path)


def write_drive_video(
    frames: Sequence[NDArray[np.uint8]],
    predicted: Sequence[float],
    expert: Sequence[float],
    path: str | Path,
    *,
    fps: int = 10,
) -> Path:
    """Frames with a steering bar: predicted (red) vs expert (green), as GIF or MP4."""
    from PIL import Image, ImageDraw

    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    imgs = []
    for f, p, e in zip(frames, predicted, expert, strict=True):
        im = Image.fromarray(np.asarray(f, dtype=np.uint8)).resize(
            (f.shape[1] * 3, f.shape[0] * 3), Image.Resampling.NEAREST
        )
        w, h = im.size
        d = ImageDraw.Draw(im)
        for val, color, y in ((e, (0, 200, 0), h - 18), (p, (230, 0, 0), h - 10)):
            x = int(w / 2 + val * w / 2 * 0.9)
            d.line([(w // 2, y), (x, y)], fill=color, width=5)
        d.text((4, 4), f"pred {p:+.2f}  expert {e:+.2f}", fill=(0, 0, 0))
        imgs.append(im)
    if not imgs:
        raise ValueError(f"{out}: no frames to write")
    if out.suffix.lower() == ".gif":
        imgs[0].save(out, save_all=True, append_images=imgs[1:], duration=int(1000 / fps), loop=0)
        return out
    from matplotlib.animation import FFMpegWriter

    if not FFMpegWriter.isAvailable():
        raise ValueError(f"{out}: writing .mp4 needs ffmpeg on the PATH (use .gif)")
    fig = new_figure(imgs[0].size[0] / DPI, imgs[0].size[1] / DPI)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.axis("off")
    art = ax.imshow(np.asarray(imgs[0]))
    writer = FFMpegWriter(fps=fps)
    with writer.saving(fig, str(out), dpi=DPI):
        for im in imgs:
            art.set_data(np.asarray(im))
            writer.grab_frame()
    return out


def render_ch6(summary: Any, out_dir: str | Path) -> list[Path]:
    """All Chapter 6 figures of a :class:`uvnav.experiments.ch6.Ch6Summary`."""
    out = Path(out_dir)
    rec = summary.record
    return [
        fig_camera_views(summary.views, out / "fig6_1_cameras.png"),
        fig_steering_histogram(
            summary.steering_all, out / "fig6_4_steering.png", title="steering before balancing"
        ),
        fig_steering_histogram(
            summary.steering_balanced, out / "fig6_5_balanced.png", title="after balancing"
        ),
        fig_split(summary.steering_train, summary.steering_val, out / "fig6_6_split.png"),
        fig_augmentation(summary.augment_examples, out / "fig6_7_augmentation.png"),
        fig_loss(rec["train_loss"], rec["val_loss"], out / "fig6_8_loss.png"),
    ]
