"""Training and augmentation of the Chapter 6 network (tiny configurations)."""

from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from uvnav.learning import PilotNetConfig, TrainConfig  # noqa: E402
from uvnav.learning.augment import augment_batch  # noqa: E402
from uvnav.learning.train import Predictor, evaluate_mse, train_pilotnet  # noqa: E402

# a smaller input than the thesis's 66x200 keeps the tests fast on two shared CPU cores
H, W = 48, 96
SMALL = PilotNetConfig(height=H, width=W, dropout=0.1)


def _road_like(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Images whose bright band sits left or right; steering follows the band's position."""
    imgs = np.full((n, H, W, 3), 60, dtype=np.uint8)
    steer = rng.uniform(-0.8, 0.8, n)
    for k in range(n):
        c = int(W / 2 + 0.4 * W * steer[k])
        imgs[k, 12:, max(c - 12, 0) : c + 12] = 200
    return imgs, steer


def test_flip_negates_steering_and_mirrors_the_image() -> None:
    g = torch.Generator().manual_seed(0)
    x = torch.rand(5, 66, 200, 3) * 255
    s = torch.tensor([0.1, -0.3, 0.0, 0.7, -1.0])
    xa, sa = augment_batch(x, s, g, flip_prob=1.0, brightness=(1.0, 1.0), zoom=(1.0, 1.0))
    assert torch.allclose(sa, -s)
    assert torch.allclose(xa, torch.flip(x, dims=[2]))
    xn, sn = augment_batch(x, s, g, flip_prob=0.0, brightness=(1.0, 1.0), zoom=(1.0, 1.0))
    assert torch.allclose(sn, s) and torch.allclose(xn, x)


def test_brightness_and_zoom_stay_in_range() -> None:
    g = torch.Generator().manual_seed(1)
    x = torch.full((8, 66, 200, 3), 100.0)
    xa, _ = augment_batch(
        x, torch.zeros(8), g, flip_prob=0.0, brightness=(0.5, 0.8), zoom=(1.0, 1.0)
    )
    per = xa.mean(dim=(1, 2, 3))
    assert bool(((per >= 50 - 1e-3) & (per <= 80 + 1e-3)).all())
    # zoom on a uniform image keeps it uniform; on a centred box it enlarges the box
    box = torch.zeros(1, 66, 200, 3)
    box[:, 23:43, 80:120] = 255.0
    xz, _ = augment_batch(
        box, torch.zeros(1), g, flip_prob=0.0, brightness=(1.0, 1.0), zoom=(1.5, 1.5)
    )
    assert float((xz > 127).sum()) > 1.8 * float((box > 127).sum())


def test_training_lowers_the_loss() -> None:
    rng = np.random.default_rng(0)
    imgs, steer = _road_like(100, rng)
    thr = 0.5 - 0.5 * np.abs(steer)
    spd = rng.uniform(10, 60, len(imgs))
    val = (imgs[:40], steer[:40], thr[:40], spd[:40])
    torch.manual_seed(0)
    from uvnav.learning.pilotnet import build_pilotnet

    model = build_pilotnet(SMALL)
    before = evaluate_mse(model, *val)[0]
    model, hist = train_pilotnet(
        (imgs, steer, thr, spd),
        val,
        model=model,
        config=TrainConfig(epochs=3, batch_size=20, augment=False, seed=0),
    )
    assert len(hist.train_loss) == 3 and len(hist.val_loss) == 3
    assert hist.val_loss[-1] < 0.7 * before
    assert hist.images_per_s > 0
    steer_pred, thr_pred = Predictor(model, threads=1)(imgs[0], float(spd[0]))
    assert -1.0 <= steer_pred <= 1.0 and -1.0 <= thr_pred <= 1.0


def test_training_is_deterministic_with_a_seed() -> None:
    rng = np.random.default_rng(3)
    imgs, steer = _road_like(20, rng)
    z = np.zeros(len(imgs))
    cfg = TrainConfig(epochs=1, batch_size=10, seed=5)
    net = PilotNetConfig(height=H, width=W, extra_inputs=0, n_outputs=1)
    _, h1 = train_pilotnet((imgs, steer, z, z), None, net=net, config=cfg)
    _, h2 = train_pilotnet((imgs, steer, z, z), None, net=net, config=cfg)
    assert h1.train_loss == h2.train_loss


def test_target_speed_head_trains_and_predicts_a_speed() -> None:
    """The "learned-speed" head: the second output learns the (scaled) target speed."""
    from uvnav.learning.pilotnet import target_speed_from_output, target_speed_label

    rng = np.random.default_rng(2)
    imgs, steer = _road_like(120, rng)
    net = PilotNetConfig(height=H, width=W, dropout=0.1, second_output="target_speed")
    # the road band's position also sets the target speed (a sharp turn ahead: slow)
    v_target = 50.0 - 25.0 * np.abs(steer)  # 30-50 m/s, below the cap
    label = target_speed_label(v_target, net)
    spd = rng.uniform(10, 60, len(imgs))
    train = (imgs[40:], steer[40:], label[40:], spd[40:])
    val = (imgs[:40], steer[:40], label[:40], spd[:40])
    cfg = TrainConfig(epochs=4, batch_size=20, augment=False, seed=0)
    model, hist = train_pilotnet(train, val, net=net, config=cfg)
    assert hist.val_throttle_mse[-1] < 0.7 * hist.val_throttle_mse[0]
    assert hist.train_loss[-1] < hist.train_loss[0]
    pred = Predictor(model)
    with pytest.raises(ValueError, match="learned-speed"):
        pred(imgs[0], 30.0)  # not a throttle
    errs = [abs(pred.outputs(imgs[k], float(spd[k]))[1] - v_target[k]) for k in range(40)]
    # better than the best constant guess (the mean), in [m/s]
    assert np.mean(errs) < np.mean(np.abs(v_target[:40] - np.mean(v_target[40:])))
    assert target_speed_from_output(target_speed_label([50.0, 150.0], net), net).tolist() == [
        50.0,
        net.target_speed_max,
    ]
    with pytest.raises(ValueError, match="target_speed"):
        target_speed_label([np.nan], net)


def test_interrupted_training_resumes_to_the_uninterrupted_result(tmp_path) -> None:
    """Stopped after epoch 1 of 3 and rerun, training continues from the saved state and ends
    with exactly the weights and curves of a run that was never stopped (dropout, shuffling and
    augmentation included); another run's state is not used."""
    rng = np.random.default_rng(4)
    imgs, steer = _road_like(40, rng)
    thr = 0.5 - 0.5 * np.abs(steer)
    spd = rng.uniform(10, 60, len(imgs))
    data = ((imgs, steer, thr, spd), (imgs[:10], steer[:10], thr[:10], spd[:10]))
    cfg = TrainConfig(epochs=3, batch_size=16, seed=1)
    whole, h_whole = train_pilotnet(*data, net=SMALL, config=cfg)

    state = tmp_path / "run.train-state.safetensors"

    class StopError(Exception):
        pass

    def stop_after_first(epoch: int, _tl: float, _vl: float) -> None:
        if epoch == 0:
            raise StopError

    with pytest.raises(StopError):
        train_pilotnet(*data, net=SMALL, config=cfg, resume=state, on_epoch=stop_after_first)
    assert state.is_file()
    ran: list[int] = []
    resumed, h_resumed = train_pilotnet(
        *data, net=SMALL, config=cfg, resume=state, on_epoch=lambda e, *_: ran.append(e)
    )
    assert ran == [1, 2]  # epoch 0 was not run again
    assert h_resumed.train_loss == h_whole.train_loss and h_resumed.val_loss == h_whole.val_loss
    for k, v in whole.state_dict().items():
        assert torch.equal(v, resumed.state_dict()[k]), k
    # a different run (another seed) ignores the state and starts from epoch 0
    ran.clear()
    other = TrainConfig(epochs=3, batch_size=16, seed=2)
    train_pilotnet(
        *data, net=SMALL, config=other, resume=state, on_epoch=lambda e, *_: ran.append(e)
    )
    assert ran == [0, 1, 2]
