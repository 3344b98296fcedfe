"""The model variants and the compiled dispatch onto their geometry and load.

Each variant is a small module stating two things:

* ``profile(x, prm) -> (height, slope)``: the plate surface's static shape, added to
  the plate's vertical motion (so Z_p(x, t) = plate(t) + height(x));
* ``load(cos_a, sin_a, prm) -> (fx, fz)``: the confining force on the block, given the
  unit tangent (cos a, sin a) of the surface under it.

Everything else (contact, friction, stepping) is shared.  Adding a variant is a
module plus one line in each dispatch function below and in ``MODELS``.
"""
from numba import njit

from . import model_a, model_b, model_c

MODEL_A, MODEL_B, MODEL_C = 0, 1, 2
MODELS = {"A": MODEL_A, "B": MODEL_B, "C": MODEL_C}
DESCRIPTIONS = {name: module.__doc__.strip().splitlines()[0]
                for name, module in (("A", model_a), ("B", model_b), ("C", model_c))}


@njit(inline="always", cache=True)
def profile(kind, x, prm):
    if kind == MODEL_A:
        return model_a.profile(x, prm)
    if kind == MODEL_B:
        return model_b.profile(x, prm)
    return model_c.profile(x, prm)


@njit(inline="always", cache=True)
def load(kind, cos_a, sin_a, prm):
    if kind == MODEL_A:
        return model_a.load(cos_a, sin_a, prm)
    if kind == MODEL_B:
        return model_b.load(cos_a, sin_a, prm)
    return model_c.load(cos_a, sin_a, prm)
