"""Codac, the peer of the speed benchmarks, imported so that it cannot change fivebar's numbers.

`import codac` sets the processor to round upward for the whole process: from then on Python
itself parses `1e-12` as 1.0000000000000002e-12, in the benchmark's code and in every module
compiled after it, and would write such constants into `__pycache__`, where later runs of fivebar
(the tests too) read them. So a benchmark imports what it needs from fivebar (and loads its
configs) first, then codac through `import_codac`, after which no bytecode is written.
"""

from __future__ import annotations

import sys


def import_codac():
    """The codac module, or None when it is not installed (a benchmark-only dependency). Call it
    after every import from fivebar_cli and every config loaded."""
    sys.dont_write_bytecode = True
    try:
        import codac
    except ImportError:
        return None
    return codac
