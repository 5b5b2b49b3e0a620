"""vfem: contact between deformable bodies by the virtual finite element method (Underhill 1992).

The Python API has the concepts of the input file (``docs/input.md``, ``docs/python-api.md``):

* a :class:`Model` is :class:`Body` objects (a scikit-fem mesh with named boundaries, a
  :class:`LinearElastic` material, :class:`Support`, :class:`PrescribedDisplacement`,
  :class:`Traction` and :class:`Platen` conditions), :class:`Contact` settings and the load
  factors of the steps;
* :func:`solve` runs it and returns an :class:`AnalysisResult`: per converged step the fields of
  every body and the contact iteration history;
* :func:`load` reads an input file into a :class:`ModelConfig`, whose ``build()`` gives the
  :class:`Model`.
"""

from __future__ import annotations

from pathlib import Path

from ._version import __version__  # noqa: F401 (vfem.__version__)
from .bodies import Body, Platen, PrescribedDisplacement, Support, Traction
from .config import BodyConfig, MeshSpec, ModelConfig, Steps
from .contact.settings import ContactSettings
from .errors import AnalysisError, InputError, VfemError
from .materials import LinearElastic
from .model import Model
from .result_types import AnalysisResult, StepResult
from .solver import Analysis

#: The contact settings under the name the input file uses (``[contact]``).
Contact = ContactSettings


def load(path: str | Path) -> ModelConfig:
    """Read and check an input file (TOML); ``load(path).build()`` is the :class:`Model`."""
    from .io.input import load as _load

    return _load(path)


def solve(model: Model | ModelConfig | str | Path, out: str | Path | None = None,
          on_step=None, resume: bool = False, solver: str | None = None,
          overwrite: bool = False) -> AnalysisResult:
    """Solve a model: a :class:`Model`, a :class:`ModelConfig` or the path of an input file.

    With ``out``, each converged step is written there as it converges (VTU files for ParaView,
    ``results.pvd``, ``contact.csv``, ``reactions.csv``, a checkpoint, ``summary.json`` of the
    steps so far); ``resume=True`` continues from the last checkpoint in ``out`` of an earlier
    run of the same model. ``on_step(step)`` is called after each converged step. An analysis
    that does not converge returns with ``converged = False`` and the steps done. ``solver``: the
    linear-algebra backend (``"superlu"``, ``"pardiso"``, ``"cholmod"``, ``"mumps"``; default:
    the one chosen with :func:`vfem.linalg.use`, else the fastest installed). ``out`` is kept
    as the command line keeps it (:mod:`vfem.io.folders`): an earlier run's files there are
    cleared, another model's are refused (:class:`InputError`) unless ``overwrite``.
    """
    base = None
    if isinstance(model, (str, Path)):
        base = Path(model).parent
        model = load(model)
    if isinstance(model, ModelConfig):
        model = model.build(base)
    if out is None:
        return Analysis(model, solver).run(on_step)
    from .io.folders import ResultsFolder, run_description
    from .io.results import run_writing

    folder = ResultsFolder(Path(out), run_description(f"vfem.solve({model.name!r})",
                                                      f"python: {model.name}", []))
    folder.prepare(overwrite=overwrite, resume=resume)
    try:
        return run_writing(model, Path(out), on_step, resume, backend=solver)[1]
    finally:
        folder.update()
        folder.stamp_summary()


__all__ = [
    "Analysis", "AnalysisError", "AnalysisResult", "Body", "BodyConfig", "Contact",
    "ContactSettings", "InputError", "LinearElastic", "MeshSpec", "Model", "ModelConfig",
    "Platen", "PrescribedDisplacement", "StepResult", "Steps", "Support", "Traction",
    "VfemError", "load", "solve",
]
