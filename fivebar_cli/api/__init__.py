"""The public Python API (`import fivebar_cli as fb`): the names of `__all__`, re-exported at the
package's top on first use. Results are immutable values (`values.py`); the `fivebar` commands are
this API's first client."""

from fivebar_cli.api import rpr3
from fivebar_cli.api.atlas import atlas, atlas_plan
from fivebar_cli.api.calls import aspects, copy_examples, examples, load, path, pave, read_qt, refine, view
from fivebar_cli.api.locations import Location, locate
from fivebar_cli.api.poses import dkp, verify
from fivebar_cli.api.studies import kratio, tolerance
from fivebar_cli.api.trees import Comparison, compare
from fivebar_cli.api.values import Aspect, Aspects, Path, Paving, Report, Table
from fivebar_cli.errors import FivebarError, InputError
from fivebar_cli.mechanisms.base import Mechanism

__all__ = [
    "load", "pave", "refine", "read_qt", "aspects", "locate", "path", "atlas", "atlas_plan", "view", "examples", "copy_examples", "rpr3",
    "tolerance", "kratio", "verify", "dkp", "compare", "Report",
    "Mechanism", "Paving", "Aspects", "Aspect", "Location", "Path", "Table", "Comparison", "FivebarError", "InputError",
]
