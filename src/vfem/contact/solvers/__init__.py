"""The contact-set solvers: the outer iteration, the complementarity problem over the pair matrix,
its bordered (platen) form, the pair matrix W (dense, or its matrix-free operator).

The public face of this stage: code outside it imports these names from here
(``tests/test_architecture.py``).
"""

from .bordered import ReusedFactor, bordered_matrix, bordered_solve
from .complementarity import linear_complementarity
from .iteration import Check, iterate
from .matrix_free import PairOperator, matrix_free_refusal
from .pair_flexibility import force_rows, pair_matrix, platen_rows
from .routes import predicted_seconds

__all__ = [
    "predicted_seconds",
    "bordered_matrix",
    "bordered_solve",
    "Check",
    "force_rows",
    "iterate",
    "linear_complementarity",
    "matrix_free_refusal",
    "pair_matrix",
    "PairOperator",
    "platen_rows",
    "ReusedFactor",
]
