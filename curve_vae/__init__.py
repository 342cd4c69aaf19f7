"""curve-vae: learn, generate and interpolate 2D curves with an Inception VAE."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("curve-vae")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0"
