"""Errors that vfem reports to its users.

Two families: :class:`InputError` for a model that cannot be analysed as given (the CLI prints the
message and exits with status 2, no traceback), and :class:`AnalysisError` for an analysis that was
set up correctly but could not be completed (a step that would not converge, a node pushed through
the outer layer of elements of another body).
"""


class VfemError(Exception):
    """Base of every error vfem raises on purpose."""


class InputError(VfemError, ValueError):
    """The model is wrong: the message names the problem and where it is (body, key, node)."""


class AnalysisError(VfemError, RuntimeError):
    """The analysis could not be completed; results of converged steps stay valid."""


class RindViolation(AnalysisError):
    """A node went deeper than the outer layer ("rind") of elements of another body (thesis §5.6).

    The step was too large for the contact surface to be found reliably; the solver cuts the step.
    """


class InvariantViolation(AnalysisError):
    """A contact solve converged to a state that breaks an invariant every contact solution must
    satisfy — force balance, no interpenetration, no tension — checked from the full-mesh
    results independently of the contact formulation (:mod:`vfem.contact.invariants.check`).

    The solver treats it as a failed step: discarded, cut and retried.
    """


# -- failure kinds: what the stop diagnosis and the step cutter read (never the message text) ----


class ContactCycling(AnalysisError):
    """The contact iteration keeps switching nodes in and out of contact without the error
    falling (:class:`~vfem.contact.state.CycleWatch`); the step is cut."""


class ContactNotConverged(AnalysisError):
    """The contact iteration reached ``contact.max_iterations`` without meeting its tolerances."""


class PlatenOffForce(ContactNotConverged):
    """The contact iteration reached ``contact.max_iterations`` with a force-controlled
    platen's reaction still off its force (its other errors may be within their tolerances)."""


class ElementInverted(AnalysisError):
    """An iterate would turn an element inside out (det F <= 0); the step is cut."""


class NewtonNotConverged(AnalysisError):
    """A large-kinematics body's own Newton iteration did not converge."""


class PlatenUnheld(AnalysisError):
    """A force-controlled platen must move its body away from every body it may touch to apply
    its force: nothing holds it, and no step size can help."""


class PlatenUnpaired(PlatenUnheld):
    """A force-controlled platen's body meets the other edge or corner first: no node of
    either lies over the other's surface, so no contact can hold it (the other body on the
    compatibility side can)."""


class SingularSystem(AnalysisError):
    """A classical baseline's global matrix is singular (a body held by nothing but contact,
    with none of its nodes in contact)."""


class ActiveSetNotSettled(AnalysisError):
    """A classical baseline's active set does not settle, or comes back to one it had left."""
