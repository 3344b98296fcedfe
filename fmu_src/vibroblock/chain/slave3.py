"""The BlockChain3 FMU's facade (FMI 3.0): the BlockChain facade's variables, with the
per-block outputs as two arrays x and vx sized by the structural parameter N.

Everything else (parameters, inputs, aggregates, errors, FMU state) is ``ChainFacade``'s;
``fmi3.Fmi3Adapter`` presents it through pythonfmu3.  The FMU script
(``fmu_src/BlockChain3.py``) is::

    @chain_fmu3(N_BLOCKS)
    class BlockChain3(Fmi3Slave):
        '''...'''
"""
from __future__ import annotations

from pythonfmu3 import Fmi3Slave
from pythonfmu3.enums import Fmi3Causality, Fmi3Initial, Fmi3Variability
from pythonfmu3.variables import Dimension, Float64, UInt64

from ..fmi import fmu_class
from ..fmi3 import Fmi3Adapter
from ..settings import ModelError
from .slave import PER_BLOCK, ChainFacade

# The cluster catalogue keeps (N + 1)(N + 6) doubles: 800 MB at this N.
MAX_BLOCKS = 10000


class ChainArrayFacade(ChainFacade):
    """``ChainFacade`` with N a structural parameter and array outputs."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.description = (f"A chain of N blocks (structural parameter, default {type(self).n_blocks}) on a "
                            "vibrating plate (Burridge-Knopoff): model A's contact and friction per block, "
                            "coupling springs between neighbours.")

    def _register_interface(self) -> None:
        self.register_variable(UInt64(
            "N", causality=Fmi3Causality.structuralParameter, variability=Fmi3Variability.fixed,
            initial=Fmi3Initial.exact,
            description=f"number of blocks, the size of x and vx (1 ... {MAX_BLOCKS}); set it first: the other "
                        "settings are kept",
            getter=lambda: self.n_blocks, setter=lambda value: self._guard(self._set_n_blocks, value)))
        self._size_reference = self.vars[len(self.vars) - 1].value_reference
        super()._register_interface()

    def _register_per_block_outputs(self) -> None:
        for name, text in PER_BLOCK.items():
            self.register_variable(Float64(
                name, causality=Fmi3Causality.output, variability=Fmi3Variability.continuous,
                initial=Fmi3Initial.calculated, description=text.format(i="i") + ", i = 1 ... N",
                dimensions=[Dimension(valueReference=str(self._size_reference))],
                getter=lambda name=name: self._block_outputs(name)))

    def _block_outputs(self, name: str) -> list:
        if not self.chain.started:
            return [0.0] * self.n_blocks
        return getattr(self.chain, name).tolist()  # (the lab's: Chain.x, Chain.vx)

    def _set_n_blocks(self, value) -> None:
        self._require_not_started("N")
        if not 1 <= int(value) <= MAX_BLOCKS:
            raise ModelError(f"N = {value!r}: a chain has 1 to {MAX_BLOCKS} blocks")
        self._restore({**self._capture(), "n_blocks": int(value)})  # a new Chain, the settings kept

    def _capture(self) -> dict:
        return {**super()._capture(), "n_blocks": self.n_blocks}

    def _restore(self, state: dict) -> None:
        previous = self.n_blocks
        self.n_blocks = int(state["n_blocks"])
        try:
            super()._restore(state)
        except Exception:
            self.n_blocks = previous
            raise


def chain_fmu3(n_blocks: int):
    """Class decorator turning ``class BlockChain3(Fmi3Slave)`` into the FMI 3.0 facade of
    a chain of N blocks, N = ``n_blocks`` unless the master sets N."""
    facade = type("BlockChain3Facade", (Fmi3Adapter, ChainArrayFacade, Fmi3Slave),
                  {"n_blocks": int(n_blocks), "__module__": __name__})
    return fmu_class(facade)
