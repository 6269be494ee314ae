"""The ``crowd:`` block of a 2D scenario file: real pedestrians replayed from a recording."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, ValidationInfo, field_validator, model_validator

from uvnav.obstacles import Obstacle
from uvnav.scenarios.errors import FieldError, ScenarioError
from uvnav.scenarios.limits import FileModel
from uvnav.scenarios.pedestrians import (
    DATASETS,
    DEFAULT_RADIUS,
    Track,
    all_positions,
    crowd_obstacles,
    episode_tracks,
    load_tracks,
)
from uvnav.scenarios.schema_types import Box, Point2

# ------------------------------------------------------------------------------------------- crowd


class CrowdSpec(FileModel):
    """Real pedestrians replayed from a recording (:mod:`uvnav.scenarios.pedestrians`).

    At build time every pedestrian whose track overlaps the episode window becomes a disc obstacle
    of ``radius`` replaying its annotations (linear interpolation between them, times shifted so
    that ``t_start`` of the recording is t = 0).  Outside its track a pedestrian is absent: it
    takes part in no collision or clearance query and is never sensed (its motion model reports
    ``present(t)``).  Pedestrians do not react to the robot.  They are
    not bound by the thesis's (2.6)-(2.8): :func:`~uvnav.scenarios.check_constraints` reports them
    as warnings only.
    """

    dataset: str = Field(
        min_length=1,
        description="shipped sequence 'eth' or 'hotel', or a path to a track file "
        "(relative paths are taken from the scenario file's folder)",
    )
    format: Literal["obsmat", "xy4", "trajnet"] = Field(
        "obsmat",
        description="file format: ETH 'obsmat' (frame id x z y vx vz vy), 'xy4' (frame id x y) or "
        "'trajnet' (TrajNet++ ndjson); ignored for the shipped sequences",
    )
    t_start: float = Field(0.0, description="recording time that becomes t = 0 [s]")
    duration: float | None = Field(
        None, gt=0, description="length of the replayed window [s]; omitted = the scene's t_max"
    )
    radius: float = Field(DEFAULT_RADIUS, gt=0, description="pedestrian disc [m]")
    frame_rate: float | None = Field(
        None,
        gt=0,
        description="frames per second of the file [1/s]; omitted = the sequence's own (eth 15, "
        "hotel 25) or, for a file, inferred from a 0.4 s annotation period",
    )
    region: Box | None = Field(
        None, description="optional crop [xmin, ymin, xmax, ymax] [m]: samples outside are absent"
    )
    scale: float = Field(
        1.0,
        gt=0,
        description="file positions are multiplied by this to give metres (before offset)",
    )
    offset: Point2 = Field((0.0, 0.0), description="added to the scaled positions [m]")
    stitch: bool = Field(
        False,
        description="join a track that ends where another starts (at most one annotation step "
        "later, within 1 m) into one person",
    )
    at_rest: bool = Field(
        False,
        description="a person whose track starts after t = 0 waits at rest at its first position "
        "from t = 0 instead of appearing then",
    )

    @field_validator("dataset")
    @classmethod
    def _resolve(cls, value: str, info: ValidationInfo) -> str:
        if value in DATASETS:
            return value
        base = (info.context or {}).get("base_dir") if info.context else None
        path = Path(value).expanduser()
        if not path.is_absolute() and base is not None:
            path = Path(base) / path
        return str(path)

    @model_validator(mode="after")
    def _readable(self) -> CrowdSpec:
        try:
            self.tracks()
        except ScenarioError as exc:
            raise FieldError("dataset", str(exc)) from None
        return self

    def tracks(self) -> dict[int, Track]:
        """All tracks of the recording (recording times) [s], [m]."""
        return load_tracks(
            self.dataset,
            self.format,
            frame_rate=self.frame_rate,
            scale=self.scale,
            offset=(float(self.offset[0]), float(self.offset[1])),
            stitch=self.stitch,
        )

    def window(self, t_max: float) -> float:
        """Length of the replayed window [s]: ``duration`` or the scene's ``t_max``."""
        return float(self.duration) if self.duration is not None else float(t_max)

    def pieces(self, t_max: float) -> list[Track]:
        """Episode-time track pieces, :func:`uvnav.scenarios.pedestrians.episode_tracks`."""
        return episode_tracks(
            self.tracks(),
            t_start=self.t_start,
            duration=self.window(t_max),
            region=self.region,
            at_rest=self.at_rest,
        )

    def to_obstacles(self, t_max: float) -> list[Obstacle]:
        """Fresh replayed disc obstacles for one episode of a scene with time limit ``t_max``."""
        tracks = self.tracks()
        centre = all_positions(tracks).mean(axis=0)
        return crowd_obstacles(self.pieces(t_max), radius=self.radius, centre=centre)
