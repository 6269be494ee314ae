"""Episodes and recordings in the ROS 2 tools' formats (the optional ``ros`` extra).

* :mod:`uvnav.bags.mcap`: a 2D episode written as an MCAP file with ROS 2 messages (CDR
  encoded, ``ros2msg`` schemas), which Foxglove and ``ros2 bag`` read (``uvnav simulate
  --mcap``).
* :mod:`uvnav.bags.replay`: a recorded rosbag2 (sqlite3 or MCAP storage) with lidar scans and
  odometry replayed through a 2D law offline (``uvnav replay``).
* :mod:`uvnav.bags.live`: the same episode served live to Foxglove over its WebSocket protocol
  with ``foxglove-sdk`` (``uvnav view``).
* :mod:`uvnav.bags.messages`: the ROS 2 message definitions (ROS 2 Jazzy's, from ``rosbags``'
  type store) and the conversions between uvnav's values and those messages.

The packages (``mcap``, ``mcap-ros2-support``, ``rosbags``, ``foxglove-sdk``) are imported
inside these modules' functions; :func:`require` says in one line which are missing.  This
package reads and writes files (and serves episodes): it sits at the top of the layers,
beside :mod:`uvnav.viz`.
"""

from __future__ import annotations

import importlib.util

#: the import names of the ``ros`` extra's packages this package uses
PACKAGES: tuple[tuple[str, str], ...] = (
    ("mcap", "mcap"),
    ("mcap_ros2", "mcap-ros2-support"),
    ("rosbags", "rosbags"),
)


class MissingExtraError(ImportError):
    """A package of the ``ros`` extra is not installed."""


def require(what: str, more: tuple[tuple[str, str], ...] = ()) -> None:
    """Check that the ``ros`` extra is installed: :data:`PACKAGES` and ``more`` (import name,
    distribution name).

    Raises:
        MissingExtraError: one line naming ``what`` needs it, the missing packages and the
            install command.
    """
    missing = [dist for mod, dist in (*PACKAGES, *more) if importlib.util.find_spec(mod) is None]
    if missing:
        raise MissingExtraError(
            f"{what} needs the 'ros' extra ({', '.join(missing)} not installed): "
            "pip install 'uvnav[ros]'"
        )
