"""The BlockChain FMU's facade: the variables of a chain of N blocks (N fixed when the
FMU is built) mapped onto a ``Chain`` (the shared FMI machinery is ``fmi.FmuFacade``).

The FMU script (``fmu_src/BlockChain.py``) is::

    @chain_fmu(N_BLOCKS)
    class BlockChain(Fmi2Slave):
        '''...'''
"""
from __future__ import annotations

from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Variability
from pythonfmu.variables import Boolean, Integer, Real, String

from ..fmi import FmuFacade, PlateInputs, fmu_class
from ..interface import INPUTS, reading_choices
from ..models import parameters_for
from ..settings import ModelError
from .runner import CHAIN_PARAMETERS, SCHEMES, Chain

# The blocks' parameters the chain offers (model A's physics; the drive spring is the leaf
# spring k_p; the single block's start and tolerance parameters do not apply).
BLOCK_PARAMETERS = ("m", "g", "k_n", "k_t", "gamma_n", "gamma_t", "mu_s", "k_d", "V_d", "A", "omega", "dt", "mu_k",
                    "v_w", "drive_angle")
# The single block's laws the chain offers, Integer parameters fixed before the start.
LAWS = ("friction_law", "plate_motion")
AGGREGATES = {
    "mean_slip_velocity": ("Real", "delta_0/tau_0", "mean of the blocks' slip velocities vx"),
    "moment_rate": ("Real", "delta_0/tau_0", "potency rate: the sum of the blocks' slip velocities"),
    "slipping_fraction": ("Real", "1", "fraction of the blocks slipping (|vx| > v_start)"),
    "event_count": ("Integer", "", "events closed since the start (catalogue rows)"),
    "last_event_potency": ("Real", "delta_0", "potency of the last closed event: the sum of its blocks' slips"),
    "last_event_magnitude": ("Real", "1", "(2/3) log10 of the last event's potency (NaN before the first)"),
    "coulomb_resets": ("Integer", "", "Coulomb resets of all blocks so far"),
    "work_input": ("Real", "m_0 delta_0^2/tau_0^2", "work done on the chain (energy_balance)"),
    "energy_dissipated": ("Real", "m_0 delta_0^2/tau_0^2", "energy dissipated (energy_balance)"),
    "energy_residual": ("Real", "m_0 delta_0^2/tau_0^2",
                        "stored energy - stored at start - work + dissipated (energy_balance)"),
}
PER_BLOCK = {"x": "displacement of block {i} from its place in the unloaded chain, in the lab [delta_0]",
             "vx": "velocity of block {i} in the lab (its slip velocity less the plate's plate_vx and drive under "
                   "plate_motion = 1) [delta_0/tau_0]"}
CATALOG_TEXT = ("path of the event catalogue (CSV, one row per event, written as events close; the thresholds "
                "v_start and v_stop are stated in its first line); empty: no file (event_count still counts)")


class ChainFacade(PlateInputs, FmuFacade):
    """FMU facade over ``vibroblock.chain.Chain``."""

    n_blocks = 16
    rejected = (ModelError,)
    what = "the chain"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.description = (f"A chain of {self.n_blocks} blocks on a vibrating plate (Burridge-Knopoff): "
                            "model A's contact and friction per block, coupling springs between neighbours.")
        self.periodic = False
        self.catalog_file = ""
        self.chain = Chain(self.n_blocks)
        self.plate_input = {name: 0.0 for name in INPUTS}
        self._input_changed = False
        self._outputs = None
        self._register_interface()

    def _register_interface(self) -> None:
        specs = {spec.name: spec for spec in parameters_for("A")}
        for name in BLOCK_PARAMETERS:
            spec, fmu_name = specs[name], "k_p" if name == "k_d" else name
            text = "leaf spring pulling each block towards the loader at V_d t" if name == "k_d" else spec.description
            self._parameter(Real, fmu_name, f"{text} [{spec.unit}]")
        for name, (_, unit, text) in CHAIN_PARAMETERS.items():
            self._parameter(Real, name, f"{text} [{unit}]")
        for name in LAWS:
            self.register_variable(Integer(
                name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
                description=f"each block's {name.replace('_', ' ')}: {reading_choices(name)}",
                getter=lambda name=name: self.chain.settings.readings[name],
                setter=lambda value, name=name: self._guard(self._set_law, name, int(value))))
        self.register_variable(Integer(
            "integrator", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description="the chain's scheme: 0 = symplectic_euler (the paper's, first order), 1 = rk4 (fourth order "
                        "between contact switches and resets, four force evaluations per step; its energy balance "
                        "closes to rounding)",
            getter=lambda: SCHEMES[self.chain.settings.integrator],
            setter=lambda value: self._guard(self._set_integrator, int(value))))
        self.register_variable(Boolean(
            "periodic", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description="periodic ends (the last block coupled to the first); else free ends",
            getter=lambda: self.periodic, setter=lambda value: self._guard(self._set_periodic, bool(value))))
        self.register_variable(Boolean(
            "energy_balance", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description="account work, dissipation and stored energy (outputs work_input, energy_dissipated, "
                        "energy_residual)",
            getter=lambda: self.chain.energy_balance,
            setter=lambda value: self._guard(self._set_energy_balance, bool(value))))
        self.register_variable(Boolean(
            "cluster_catalog", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description="catalogue events as clusters of slipping blocks connected in space and time (two events at "
                        "two places are two); else chain-wide (an event ends when every block is below v_stop)",
            getter=lambda: self.chain.clusters, setter=lambda value: self._guard(self._set_clusters, bool(value))))
        self.register_variable(Boolean(
            "jump_sticks", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description="while every block sticks, jump to shortly before the next failure in closed form instead of "
                        "stepping through the stick (symplectic_euler, friction_law 0-2, plate at rest; elsewhere "
                        "the run steps; refused with energy_balance); the same events, the state to rounding",
            getter=lambda: self.chain.jump_sticks,
            setter=lambda value: self._guard(self._set_jump_sticks, bool(value))))
        self.register_variable(String(
            "catalog_file", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description=CATALOG_TEXT, getter=lambda: self.catalog_file,
            setter=lambda value: self._guard(self._set_catalog_file, str(value))))
        for name, (unit, text) in INPUTS.items():
            self.register_variable(Real(
                name, causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                description=f"{text} [{unit}]", getter=lambda name=name: self.plate_input[name],
                setter=lambda value, name=name: self._guard(self._set_input, name, value)))
        types = {"Real": Real, "Integer": Integer}
        for name, (kind, unit, text) in AGGREGATES.items():
            self.register_variable(types[kind](
                name, causality=Fmi2Causality.output, initial=Fmi2Initial.calculated,
                variability=Fmi2Variability.continuous if kind == "Real" else Fmi2Variability.discrete,
                description=f"{text} [{unit}]" if unit else text,
                getter=lambda name=name: self._output(name)))
        self._register_per_block_outputs()

    def _register_per_block_outputs(self) -> None:
        """FMI 2.0 has no arrays: one scalar per block and output, x[1] ... x[N]."""
        for name, text in PER_BLOCK.items():
            for i in range(self.n_blocks):
                self.register_variable(Real(
                    f"{name}[{i + 1}]", causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                    initial=Fmi2Initial.calculated, description=text.format(i=i + 1),
                    getter=lambda name=name, i=i: self._block_output(name, i)))

    def _parameter(self, kind, name: str, description: str) -> None:
        self.register_variable(kind(
            name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed, description=description,
            getter=lambda: self.chain.parameter(name),
            setter=lambda value: self._guard(self.chain.set_parameter, name, value)))

    # ------------------------------------------------------------------ setters
    def _set_periodic(self, periodic: bool) -> None:
        self._require_not_started("periodic")
        self.periodic = periodic
        self.chain.periodic = periodic

    def _set_law(self, name: str, value: int) -> None:
        self._require_not_started(name)
        self.chain.settings.set_reading(name, value)

    def _set_integrator(self, value: int) -> None:
        self._require_not_started("integrator")
        self.chain.set_integrator(value)

    def _set_energy_balance(self, track: bool) -> None:
        self._require_not_started("energy_balance")
        self.chain.energy_balance = track

    def _set_clusters(self, clusters: bool) -> None:
        self._require_not_started("cluster_catalog")
        self.chain.clusters = clusters

    def _set_jump_sticks(self, jump: bool) -> None:
        self._require_not_started("jump_sticks")
        self.chain.jump_sticks = jump

    def _set_catalog_file(self, path: str) -> None:
        self._require_not_started("catalog_file")
        self.catalog_file = path

    def _require_not_started(self, name: str) -> None:
        if self.chain.started:
            raise ModelError(f"{name} cannot change during a run")

    # ------------------------------------------------------------------ outputs
    def _changed(self) -> None:
        self._outputs = None

    def _output(self, name: str):
        if not self.chain.started:
            return 0.0
        if self._outputs is None:
            self._outputs = self.chain.outputs()
        return self._outputs[name]

    def _block_output(self, name: str, i: int) -> float:
        if not self.chain.started:
            return 0.0
        return self.chain.lab(name, i)

    # ------------------------------------------------------------------ facade hooks
    def _is_started(self) -> bool:
        return self.chain.started

    def _time(self) -> float:
        return self.chain.time

    def _start(self, start_time: float) -> None:
        from .catalog import CatalogFile
        self.chain.catalog_file = CatalogFile(self.catalog_file) if self.catalog_file else None
        self.chain.start(start_time)
        self._apply_input()

    def _apply_input(self) -> None:
        if self._input_changed:
            self.chain.set_plate_input(*(self.plate_input[name] for name in INPUTS))
            self._input_changed = False

    def _advance_to(self, end_time: float) -> None:
        self._apply_input()
        self.chain.advance_to(end_time)

    def _capture(self) -> dict:
        return {"chain": self.chain.get_state() if self.chain.started else None, "start_time": self.start_time,
                "plate_input": dict(self.plate_input), "input_changed": self._input_changed,
                "parameters": {name: self.chain.parameter(name) for name in self._parameter_names()},
                "periodic": self.periodic, "energy_balance": self.chain.energy_balance,
                **{name: self.chain.settings.readings[name] for name in LAWS}, "clusters": self.chain.clusters,
                "jump_sticks": self.chain.jump_sticks,
                "integrator": self.chain.settings.integrator,
                "catalog_file": self.catalog_file}

    def _parameter_names(self):
        return [("k_p" if name == "k_d" else name) for name in BLOCK_PARAMETERS] + list(CHAIN_PARAMETERS)

    def _restore(self, state: dict) -> None:
        chain = Chain(self.n_blocks, periodic=bool(state["periodic"]), energy_balance=bool(state["energy_balance"]),
                      **{name: int(state.get(name, 0)) for name in LAWS}, clusters=bool(state["clusters"]),
                      integrator=str(state["integrator"]), jump_sticks=bool(state.get("jump_sticks", False)),
                      **{name: float(value) for name, value in state["parameters"].items()})
        if state["chain"] is not None:
            chain.set_state(state["chain"])
            from .catalog import CatalogFile
            chain.catalog_file = CatalogFile(state["catalog_file"]) if state["catalog_file"] else None
        self.plate_input = {name: float(state["plate_input"][name]) for name in INPUTS}
        self.start_time, self._input_changed = float(state["start_time"]), bool(state["input_changed"])
        self.periodic, self.catalog_file, self.chain = bool(state["periodic"]), str(state["catalog_file"]), chain


def chain_fmu(n_blocks: int):
    """Class decorator turning ``class BlockChain(Fmi2Slave)`` into the facade of a chain
    of ``n_blocks`` blocks."""
    facade = type("BlockChainFacade", (ChainFacade,), {"n_blocks": int(n_blocks), "__module__": __name__})
    return fmu_class(facade)
