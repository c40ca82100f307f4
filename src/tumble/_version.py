"""tumble's version, read from the installed package's metadata.

``pyproject.toml`` is the single place the version is written; installing tumble (``pip install
-e .``) copies it into the metadata read here. :mod:`tumble.io` and :mod:`tumble.rigid` stamp it
on the datasets they write; ``tumble.__version__`` is this value.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("tumble")
except PackageNotFoundError:  # a source tree on sys.path that was never installed
    __version__ = "0+unknown"
