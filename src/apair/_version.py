"""apair's version, in one place (`apair.__version__`, the CLI's --version, the cache keys)."""

__version__ = "0.1.0"
