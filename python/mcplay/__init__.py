"""mcplay: a Monte Carlo estimator playground as a Python package.

Placeholder of the build helper (the Python layer replaces it): the extension only.
"""

# Running from the source tree, the extension lives in the build folder's mcplay/ (CMake puts it
# in build/python/mcplay): with both folders on PYTHONPATH this makes them one package.
__path__ = __import__("pkgutil").extend_path(__path__, __name__)

from ._core import McplayError, version  # noqa: E402

__all__ = ["McplayError", "version"]
__version__ = version()
