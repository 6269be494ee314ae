"""Layer 2: what a robot can know — exact range-limited obstacle readings and a lidar scanner."""

from uvnav.sensors.exact import lidar_scan, sense_obstacles
from uvnav.sensors.observation import LidarScan, Observation, ObstacleReading

__all__ = ["LidarScan", "Observation", "ObstacleReading", "lidar_scan", "sense_obstacles"]
