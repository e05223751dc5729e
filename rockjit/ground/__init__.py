"""Ground motions: the block under acceleration pulses and recorded earthquakes.

One concept per module:

- :mod:`~rockjit.ground.records`: the readers of recorded motions (arrays, PEER ``.AT2``,
  two-column text or CSV);
- :mod:`~rockjit.ground.fema`: the FEMA P695 record sets (the ``records`` extra);
- :mod:`~rockjit.ground.settings`: :class:`Transient`, how a transient run is integrated;
- :mod:`~rockjit.ground.response`: :class:`TransientResult` and the outcome codes;
- :mod:`~rockjit.ground.reference`: one run on the scipy reference path;
- :mod:`~rockjit.ground.compiled`: the compiled path: a batch's cells in parallel, or one run;
- :mod:`~rockjit.ground.plan`: a single run's plan (what :func:`rockjit.simulate` builds);
- :mod:`~rockjit.ground.batch`: a batch of cells, the kernels that compute their outcomes and
  the method (the compiled path or which scipy path);
- :mod:`~rockjit.ground.spectrum`: overturning spectra of pulses;
- :mod:`~rockjit.ground.fitting`: lognormal fragility fits by maximum likelihood;
- :mod:`~rockjit.ground.fragility`: incremental dynamic analysis over a record set;
- :mod:`~rockjit.ground.closed_forms`: the slender linearised block's closed forms;
- :mod:`~rockjit.ground.figures`: the spectra's and fragility curves' figures.

docs/theory/ground-motions.md has the theory, docs/guide/earthquakes.md the guide.
"""

from .fema import fema_set
from .fitting import LognormalFit, fit_capacities, fit_lognormal
from .fragility import FragilityResult, fragility
from .records import read_at2, read_record, read_table
from .response import OUTCOMES, TransientResult
from .settings import Transient
from .spectrum import SpectrumResult, spectrum

__all__ = ["FragilityResult", "HarmonicSum", "LognormalFit", "OUTCOMES", "Pulse", "Record",
           "SpectrumResult", "Transient", "TransientResult", "fema_set", "fit_capacities", "fit_lognormal",
           "fragility", "read_at2", "read_record", "read_table", "spectrum"]

from .plan import plan_run  # noqa: E402
from ..plugs import HarmonicSum, Pulse, Record, TransientPlug  # noqa: E402

# A single run under a transient excitation (an excitation plug, rockjit.plugs: a pulse, a
# record, a sum of harmonics) takes the transient path: rockjit.simulate asks the excitation
# for its plan (Excitation.plan_run), and the plugs answer here, above both the excitations and
# their runs (importing rockjit imports this package, so the answer is always in place).
TransientPlug.plan_run = plan_run
