"""The contact-set solvers: the outer iteration, the complementarity problem over the pair matrix,
its bordered (platen) form and its matrix-free operator.

The public face of this stage: code outside it imports these names from here
(``tests/test_architecture.py``).
"""

from .bordered import ReusedFactor, bordered_matrix, bordered_solve
from .complementarity import linear_complementarity
from .iteration import Check, iterate
from .matrix_free import PairOperator, matrix_free_refusal

__all__ = [
    "bordered_matrix",
    "bordered_solve",
    "Check",
    "iterate",
    "linear_complementarity",
    "matrix_free_refusal",
    "PairOperator",
    "ReusedFactor",
]
