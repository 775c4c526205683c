"""servoctl: the PC side of the open servo firmware."""
try:
    from importlib.metadata import PackageNotFoundError, version as _version

    __version__ = _version("servoctl")
except PackageNotFoundError:  # run from the source tree, not installed
    __version__ = "0.1.0"
