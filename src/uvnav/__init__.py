"""uvnav: real-time navigation of unmanned vehicles."""

__version__ = "0.1.0"
