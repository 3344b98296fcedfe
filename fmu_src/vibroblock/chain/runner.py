"""A chain of blocks on the vibrating plate (Burridge-Knopoff): the runner the
BlockChain FMU and the harness drive, as ``Block`` is for one block.

Every block is a single block of model A (default; B or C with ``model``: the blocks sit a
whole number of corrugation wavelengths apart, so the profile under block i is taken at
its displacement x_i) with the single block's laws and scheme,
``symplectic_euler`` (default) or ``rk4`` (``chain.kernel``); the chain adds the
coupling springs k_c between neighbours, a leaf spring k_p (the single block's drive
spring k_d) per block, per-block mu_s and weights drawn from a seeded distribution, and
the event catalogue.  Outputs are at the grid point at or
before the requested time (a communication step that is a multiple of dt hits the grid).

The plate is shaken by the single block's plate law (``plate_motion``: vertical, or
oblique along ``drive_angle`` with the inputs plate_x, plate_vx, plate_ax); under the
oblique law the blocks' state is kept in the plate's frame (``chain.kernel``), ``x`` and
``vx`` are the lab's, and the slip velocities (events, aggregates) are relative to the
plate.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import layout as L
from .. import run_arrays
from ..initial_state import place
from ..laws import friction_law_parameters
from ..observation import contact_energy, stored_energy
from ..settings import ModelError, Settings
from . import jump as J
from . import kernel as K
from .catalog import CatalogFile, magnitude
from .clusters import N_CLU

GRID_TOLERANCE = 1e-6
# The schemes the chain's kernel runs, and the bound each puts on dt^2 k/m for the
# stiffest spring (rk4's as the single block's check asks).
SCHEMES = {"symplectic_euler": K.SYMPLECTIC_EULER, "rk4": K.RK4}
STABLE = {"symplectic_euler": 1.0, "rk4": 4.0}
LAB_SLOTS = {"x": (L.Y_X, 0), "vx": (L.Y_VX, 1)}  # an output's state slot and its part of kernel.lab_offset
CATALOG_ROWS = 4096  # rows the kernel fills before the runner empties them
# The chain's own parameters: name -> (default, unit, description).  The blocks'
# parameters are model A's, with the drive spring k_d called k_p (the leaf spring).
CHAIN_PARAMETERS = {
    "k_c": (1.0, "m/tau_0^2", "coupling spring between neighbouring blocks (l^2 = k_c/k_p = 100 by default)"),
    "v_start": (0.3, "delta_0/tau_0", "slip speed |vx| above which a block slips: opens an event"),
    "v_stop": (0.1, "delta_0/tau_0", "an event closes once every block's slip speed is below this (above the "
                                      "ringing of a block that has stuck again)"),
    "mu_s_spread": (0.0, "1", "heterogeneity: each block's mu_s is mu_s (1 + mu_s_spread u), u uniform in [-1, 1]"),
    "load_spread": (0.0, "1", "heterogeneity: each block's weight (its normal load) is m g (1 + load_spread u'), u' "
                              "uniform in [-1, 1], drawn after the mu_s draws"),
    "rs_a_spread": (0.0, "1", "heterogeneity under rate-and-state friction: each block's rs_a is rs_a (1 + rs_a_spread "
                              "u), u uniform in [-1, 1], drawn after the loads"),
    "rs_b_spread": (0.0, "1", "heterogeneity under rate-and-state friction: each block's rs_b is rs_b (1 + rs_b_spread "
                              "u), drawn after the rs_a draws"),
    "rs_D_c_spread": (0.0, "1", "heterogeneity under rate-and-state friction: each block's rs_D_c is rs_D_c (1 + "
                                "rs_D_c_spread u), drawn after the rs_b draws"),
    "seed": (0.0, "1", "seed of the heterogeneity's random draw (an integer)"),
}
# The heterogeneity: each spread and the block parameter it spreads, in the order of their
# draws (each takes the generator's next N uniform draws, so adding one leaves the draws
# of those before it as they were).
SPREADS = (("mu_s_spread", "mu_s"), ("load_spread", "g"), ("rs_a_spread", "rs_a"), ("rs_b_spread", "rs_b"),
           ("rs_D_c_spread", "rs_D_c"))
MODEL_SPREADS, LAW_SPREADS = SPREADS[:2], SPREADS[2:]  # of the model's parameters; of a friction law's own


# The blocks' defaults where they differ from model A's: the loading of the single block's
# stick-slip benchmarks (a loading cycle of ~5e3 tau_0 instead of the paper's ~5e7) and a
# step the contact resolves (30 steps per contact period), so that catalogues of
# thousands of events take minutes.
BLOCK_DEFAULTS = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3, "dt": 1e-2}


def chain_defaults() -> dict:
    return {name: value for name, (value, _, _) in CHAIN_PARAMETERS.items()}


class Chain:
    """N blocks in a row on the vibrating plate.  Typical use::

        chain = Chain(16, A=0.5, omega=0.8)
        chain.start()
        chain.advance_to(1e4)
        chain.outputs()["event_count"], chain.x
    """

    def __init__(self, n_blocks: int = 16, *, periodic: bool = False, energy_balance: bool = False,
                 clusters: bool = False, catalog_path: str | Path | None = None,
                 integrator: str | int = "symplectic_euler", model: str = "A", jump_sticks: bool = False,
                 **parameters):
        if not (isinstance(n_blocks, (int, np.integer)) and n_blocks >= 1):
            raise ModelError(f"n_blocks = {n_blocks!r}: a chain has at least one block")
        self.n_blocks, self.periodic, self.energy_balance = int(n_blocks), bool(periodic), bool(energy_balance)
        # The catalogue: chain-wide events (an event ends when every block is below v_stop),
        # or clusters of slipping blocks connected in space and time (``chain.clusters``).
        self.clusters = bool(clusters)
        # Jump through the sticks of the whole chain (``chain.jump``): where the run is in
        # the jump's domain (``jumps_possible``), else it steps as without.
        self.jump_sticks = bool(jump_sticks)
        self.jumped_steps = 0
        # Tests for a jump come every JUMP_EVERY << jump_backoff steps: each one that finds
        # no jump doubles the interval (up to JUMP_EVERY << MAX_BACKOFF), a jump resets it.
        self.jump_backoff = 0
        self._modes = None
        self.chain_parameters = chain_defaults()
        block = dict(BLOCK_DEFAULTS)
        for name, value in parameters.items():
            if name in self.chain_parameters:
                self.chain_parameters[name] = float(value)
            else:
                block["k_d" if name == "k_p" else name] = value
        self.started = False
        self.settings = Settings(model, integrator, 0, self.energy_balance, **block)
        self.set_integrator(self.settings.integrator)
        self.catalog_file = CatalogFile(catalog_path) if catalog_path else None
        self.started = False

    # ------------------------------------------------------------------ settings
    def set_integrator(self, integrator: str | int) -> None:
        """``symplectic_euler`` (0, default) or ``rk4`` (1): the chain's kernel runs these two."""
        if self.started:
            raise ModelError("integrator cannot change during a run")
        self.settings.set_integrator(integrator)
        if self.settings.integrator not in SCHEMES:
            chosen, self.settings.integrator = self.settings.integrator, "symplectic_euler"
            raise ModelError(f"integrator = {chosen}: the chain runs symplectic_euler (0) or rk4 (1)")

    def set_parameter(self, name: str, value: float) -> None:
        if self.started:
            raise ModelError(f"{name} cannot change during a run")
        if name in self.chain_parameters:
            if not math.isfinite(value):
                raise ModelError(f"{name} = {value!r} is not finite")
            self.chain_parameters[name] = float(value)
        else:
            self.settings.set_parameter("k_d" if name == "k_p" else name, value)

    def parameter(self, name: str) -> float:
        if name in self.chain_parameters:
            return self.chain_parameters[name]
        return self.settings.parameters["k_d" if name == "k_p" else name]

    def _check(self) -> None:
        p = self.chain_parameters
        if not p["k_c"] >= 0.0:
            raise ModelError(f"k_c = {p['k_c']!r} must be >= 0")
        if not 0.0 < p["v_stop"] <= p["v_start"]:
            raise ModelError(f"the event thresholds must be 0 < v_stop <= v_start (v_stop = {p['v_stop']!r}, "
                             f"v_start = {p['v_start']!r})")
        if not 0.0 <= p["mu_s_spread"] < 1.0:
            raise ModelError(f"mu_s_spread = {p['mu_s_spread']!r} must be in [0, 1): every mu_s stays positive")
        if not 0.0 <= p["load_spread"] < 1.0:
            raise ModelError(f"load_spread = {p['load_spread']!r} must be in [0, 1): every block keeps a weight")
        model = self.settings.model
        for spread, name in MODEL_SPREADS:
            if p[spread] > 0.0 and name not in self.settings.parameters:
                raise ModelError(f"{spread} = {p[spread]!r} spreads {name}, which model {model} does not have")
        law = friction_law_parameters(self.settings.readings)
        for spread, name in LAW_SPREADS:
            if not 0.0 <= p[spread] < 1.0:
                raise ModelError(f"{spread} = {p[spread]!r} must be in [0, 1): every {name} keeps its sign")
            if p[spread] > 0.0 and name not in law:
                raise ModelError(f"{spread} = {p[spread]!r} spreads {name}, a parameter of rate-and-state friction "
                                 f"(friction_law = 3 or 4); friction_law = {self.settings.readings['friction_law']} "
                                 f"has no {name}")
        if p["seed"] != int(p["seed"]) or p["seed"] < 0:
            raise ModelError(f"seed = {p['seed']!r} must be a non-negative integer")
        if self.jump_sticks and self.energy_balance:
            raise ModelError("jump_sticks with energy_balance: a jump does not book the work and the dissipation "
                             "over the stick; turn one of them off")
        # The coupling is one more spring on each block: the scheme's stability bound
        # (which Settings checks for k_n, k_t, k_d) with the stiffest coupling mode, 4 k_c.
        m, dt = self.settings.parameters["m"], self.settings.parameters["dt"]
        stiffest = self.settings.parameters["k_t"] + self.settings.parameters["k_d"] + 4.0 * p["k_c"]
        bound = STABLE[self.settings.integrator]
        if dt * dt * stiffest / m > bound:
            raise ModelError(f"dt = {dt!r} is too large for the coupling: dt^2 (k_t + k_p + 4 k_c)/m = "
                             f"{dt * dt * stiffest / m:.3g} > {bound:g} ({self.settings.integrator}); take "
                             f"dt <= {math.sqrt(bound * m / stiffest):.3g}")

    # ------------------------------------------------------------------ running
    def start(self, t0: float = 0.0) -> None:
        if not math.isfinite(t0):
            raise ModelError(f"start time {t0!r} is not finite")
        self.settings.check()
        self._check()
        y, self.cnt, self.drv, prm = run_arrays.fresh(self.settings.parameters, t0, self.settings.readings)
        self.Y = np.ascontiguousarray(np.tile(y, (self.n_blocks, 1)))
        self.PRM = np.ascontiguousarray(np.tile(prm, (self.n_blocks, 1)))
        for name, values in self.drawn().items():
            self.PRM[:, L.slot(name)] = values
        # Each block rests at its own weight's penetration, as a single block of that weight would.
        for i in range(self.n_blocks):
            place(self.settings, self.PRM[i], self.drv, self.Y[i])
        p = self.chain_parameters
        self.chn = np.array([p["k_c"], float(self.periodic), p["v_start"], p["v_stop"], float(self.clusters),
                             float(SCHEMES[self.settings.integrator])])
        self.evt = np.zeros(K.N_EVT)
        self.scratch = np.zeros((self.n_blocks, K.N_SCRATCH))
        self.clu = np.zeros((self.n_blocks + 1, N_CLU + self.n_blocks) if self.clusters else (1, N_CLU))
        self.rows = self._catalogue_rows()
        self.events: list[tuple] = []
        self.time = float(t0)
        plate_z = self.drv[L.D_AMP] * math.sin(self.drv[L.D_PHASE])  # (the drive's vertical part: A if vertical)
        for i, penetration in enumerate(K.penetrations(self.settings.kind, self.Y, self.PRM, plate_z)):
            self.Y[i, L.Y_E_NORMAL] = contact_energy(self.settings, self.PRM[i], penetration)
        self.energy_at_start = self.stored_energy(plate_z)
        self.started = True
        if self.catalog_file is not None:
            self.catalog_file.begin(self.describe_thresholds())

    def drawn(self) -> dict[str, np.ndarray]:
        """Each block's value of every spread parameter (``SPREADS``): the model's value v
        times (1 + spread u_i), u_1 ... u_N the next N uniform draws in [-1, 1] of numpy's
        ``default_rng(seed)``, one batch per spread in ``SPREADS``' order, drawn whether the
        spread is set or not (so each parameter's draws depend on the seed alone).  A
        spread of 0 leaves the model's value to the bit.  Spreading g scales the block's
        weight m g, its only normal load on model A's flat plate, and leaves its mass, so
        its inertia, as it is."""
        p, n = self.chain_parameters, self.n_blocks
        rng = np.random.default_rng(int(p["seed"]))
        values = {}
        for spread, name in SPREADS:
            draw = rng.uniform(-1.0, 1.0, n)
            if name not in self.settings.parameters:  # (model C has no g: its load is P_l)
                continue
            values[name] = np.full(n, self.settings.parameters[name])
            if p[spread] > 0.0:
                values[name] *= 1.0 + p[spread] * draw
        return values

    def heterogeneity(self) -> tuple[np.ndarray, np.ndarray]:
        """Each block's mu_s and gravity (:meth:`drawn`)."""
        drawn = self.drawn()
        return drawn["mu_s"], drawn["g"]

    def set_velocities(self, vx) -> None:
        """Give the blocks these slip velocities at the start (a kick, e.g. along a normal
        mode); the stored energy at the start counts them."""
        self._require_started()
        vx = np.asarray(vx, dtype=float)
        if self.cnt[L.C_STEP] != 0 or vx.shape != (self.n_blocks,) or not np.all(np.isfinite(vx)):
            raise ModelError(f"set_velocities takes {self.n_blocks} finite velocities, before the first step")
        self.Y[:, L.Y_VX] = vx
        self.energy_at_start = self.stored_energy()

    def _catalogue_rows(self):
        """The rows the kernel fills before the runner empties them: a step of the cluster
        catalogue can close a cluster per slot."""
        rows = max(CATALOG_ROWS, 2 * (self.n_blocks + 1)) if self.clusters else CATALOG_ROWS
        return np.zeros((rows, K.N_ROW))

    def set_plate_input(self, z: float, v: float, a: float, *along_x: float) -> None:
        """External plate motion from the current time on, as ``Block.set_plate_input``:
        ``along_x`` = (x, vx, ax) under plate_motion = 1 (oblique) only."""
        run_arrays.check_plate_input((z, v, a, *along_x), self.settings.readings)
        self._require_started()
        run_arrays.set_plate_input(self.drv, self.time, z, v, a, *along_x)

    def advance_to(self, t_end: float) -> None:
        """Advance to the grid point at or before t_end; on failure the state is kept."""
        self._require_started()
        if not self.time < t_end < math.inf:
            raise ModelError(f"cannot advance from t = {self.time!r} to t = {t_end!r}: "
                             "the end time must be finite and later than the current time")
        t0, dt = self.drv[L.D_T0], self.drv[L.D_DT]
        target = math.floor((t_end - t0) / dt + GRID_TOLERANCE)
        kept = (self.Y.copy(), self.cnt.copy(), self.evt.copy(), self.scratch.copy(), self.clu.copy(),
                self.jumped_steps, self.jump_backoff)
        jumping = self.jumps_possible()
        while self.cnt[L.C_STEP] < target:
            jump_every = J.JUMP_EVERY << self.jump_backoff if jumping else 0
            status = K.advance(self.settings.kind, self.Y, self.PRM, self.cnt, self.drv, self.chn, self.evt,
                               self.scratch, self.rows, self.clu, (int(target - self.cnt[L.C_STEP]), jump_every),
                               self.energy_balance)
            if status == K.NON_FINITE:
                self.Y, self.cnt, self.evt, self.scratch, self.clu, self.jumped_steps, self.jump_backoff = kept
                raise ModelError(f"the chain's state became non-finite between t = {self.time!r} and {t_end!r} "
                                 f"(dt = {dt!r}): a smaller dt, or softer springs; the state at t = {self.time!r} "
                                 "is kept")
            self._take_events()
            if status == K.STUCK:
                self._jump(int(target - self.cnt[L.C_STEP]))
        self.time = float(t_end)

    # Where a jump can happen: symplectic Euler on model A's flat plate at rest (not on a
    # corrugated plate, where x moves the contact), the friction laws whose stick is the
    # plain Cundall-Strack spring (0, 1, 2), every other reading and law at its default.
    JUMP_LAWS = (0, 1, 2)

    def jumps_possible(self) -> bool:
        """Whether this run can jump through sticks now (``jump_sticks`` on and the run in
        the jump's domain: model A, ``symplectic_euler``, friction law 0, 1 or 2 with every other
        reading and law at model A's default, the plate at rest: no drive amplitude, no
        plate input moving it).  Outside it the run steps, to the bits of a run without."""
        if not (self.jump_sticks and self.started and self.settings.integrator == "symplectic_euler"
                and not self.energy_balance and self.settings.model == "A"):
            return False
        readings = self.settings.readings
        if any(value != 0 for name, value in readings.items() if name != "friction_law"):
            return False
        if readings.get("friction_law", 0) not in self.JUMP_LAWS:
            return False
        drv = self.drv
        return drv[L.D_AMP] == 0.0 and drv[L.D_EXT_V] == 0.0 and drv[L.D_EXT_A] == 0.0 and drv[L.D_AMP_X] == 0.0

    def _jump(self, n_cap: int) -> None:
        """Every block sticks quietly (``kernel.advance`` said STUCK): jump through as much
        of the stick as is safe (``chain.jump``), or step on where none is (and test less
        often until a jump is taken)."""
        if n_cap < J.JUMP_EVERY:
            return
        self.jump_backoff = min(self.jump_backoff + 1, J.MAX_BACKOFF)
        normals = np.empty(self.n_blocks)
        K.rest_probe(self.settings.kind, self.Y, self.PRM, self.cnt, self.drv, normals)
        if self._modes is None:
            self._modes = J.Modes(self.n_blocks, self.periodic)
        planned = J.plan(self, self._modes, normals, n_cap)
        if planned is not None and planned[0] >= J.JUMP_EVERY:
            self.jumped_steps += J.apply(self, planned)
            self.jump_backoff = 0

    def _take_events(self) -> None:
        """Move the events the kernel closed into the catalogue (and its file)."""
        rows = int(self.evt[K.E_ROWS])
        if rows:
            closed = [tuple(float(v) for v in row) for row in self.rows[:rows]]
            self.events.extend(closed)
            if self.catalog_file is not None:
                self.catalog_file.append(closed)
            self.evt[K.E_ROWS] = 0.0

    def _require_started(self) -> None:
        if not self.started:
            raise ModelError("the run has not started: call start() (FMI: exit initialization mode) first")

    # ------------------------------------------------------------------ observing
    x = property(lambda self: self._lab(L.Y_X, 0), doc="Each block's displacement in the lab.")
    vx = property(lambda self: self._lab(L.Y_VX, 1), doc="Each block's velocity in the lab.")
    slip_velocity = property(lambda self: self.Y[:, L.Y_VX].copy(),
                             doc="Each block's velocity relative to the plate (vx under vertical shaking).")

    def _lab(self, slot: int, which: int, block: int | None = None):
        """The blocks' slot ``slot`` in the lab (of one ``block``, else of all): the plate
        frame's plus the plate's position (which = 0) or velocity (1) under the oblique
        plate law (``kernel.lab_offset``)."""
        values = self.Y[:, slot].copy() if block is None else float(self.Y[block, slot])
        if run_arrays.plate_law(self.settings.readings).SIDEWAYS:
            values += K.lab_offset(self.settings.kind, self.drv, self.cnt)[which]
        return values

    def lab(self, name: str, block: int) -> float:
        """One block's ``x`` or ``vx`` in the lab, as ``Chain.x[block]`` (an FMU's scalar
        output reads one block without copying all)."""
        return self._lab(*LAB_SLOTS[name], block)
    mu_s = property(lambda self: self.PRM[:, L.P_MUS].copy(), doc="Each block's static friction coefficient.")
    gravity = property(lambda self: self.PRM[:, L.P_G].copy(), doc="Each block's g: its weight is m g.")
    grid_time = property(lambda self: float(self.drv[L.D_T0] + self.cnt[L.C_STEP] * self.drv[L.D_DT]))

    def plate_height(self) -> float:
        """The plate height at the stored grid state (what the kernel's last step used)."""
        from ..integrators.plate import plate_after
        return float(plate_after(self.drv, self.cnt, int(self.cnt[L.C_STEP]), 0.0)[0])

    def stored_energy(self, plate_z: float | None = None) -> float:
        """Each block's stored energy as the single block books it (kinetic, leaf spring,
        friction spring, contact: ``observation.stored_energy``), and the coupling springs',
        at the stored grid state."""
        plate_z = self.plate_height() if plate_z is None else plate_z
        Y, t, obs = self.Y, self.grid_time, np.zeros(L.N_OBS)
        total = 0.0
        for i, penetration in enumerate(K.penetrations(self.settings.kind, Y, self.PRM, plate_z)):
            obs[L.O_X], obs[L.O_VX], obs[L.O_VZ], obs[L.O_F] = Y[i, L.Y_X], Y[i, L.Y_VX], Y[i, L.Y_VZ], Y[i, L.Y_F]
            obs[L.O_PENETRATION] = penetration
            total += stored_energy(self.settings, self.PRM[i], obs, t)
        bonds = np.diff(Y[:, L.Y_X])
        if self.periodic and self.n_blocks > 1:  # (two blocks with periodic ends: two springs between them)
            bonds = np.append(bonds, Y[0, L.Y_X] - Y[-1, L.Y_X])
        return total + 0.5 * self.chain_parameters["k_c"] * float(np.sum(bonds * bonds))

    def outputs(self) -> dict:
        """The aggregates a master plots."""
        self._require_started()
        vx = self.Y[:, L.Y_VX]
        residual = 0.0
        if self.energy_balance:
            residual = (self.stored_energy() - self.energy_at_start - float(np.sum(self.Y[:, L.Y_WORK]))
                        + float(np.sum(self.Y[:, L.Y_DISSIPATED])))
        last = float(self.evt[K.E_LAST])
        return {
            "mean_slip_velocity": float(np.mean(vx)),
            "moment_rate": float(np.sum(vx)),
            "slipping_fraction": float(np.mean(np.abs(vx) > self.chain_parameters["v_start"])),
            "event_count": int(self.evt[K.E_CLOSED]),
            "last_event_potency": last,
            "last_event_magnitude": magnitude(last),
            "coulomb_resets": int(np.sum(self.scratch[:, K.S_RESETS])),
            "work_input": float(np.sum(self.Y[:, L.Y_WORK])),
            "energy_dissipated": float(np.sum(self.Y[:, L.Y_DISSIPATED])),
            "energy_residual": float(residual),
        }

    def describe_thresholds(self) -> str:
        p = self.chain_parameters
        if self.clusters:
            rule = (f"events as clusters: a block slips from |vx| > v_start = {p['v_start']:g} until |vx| < "
                    f"v_stop = {p['v_stop']:g}, slipping neighbours share a cluster, a cluster ends when none of "
                    "its blocks slips")
        else:
            rule = (f"event start: a block's |vx| > v_start = {p['v_start']:g}; end: every |vx| < v_stop = "
                    f"{p['v_stop']:g}")
        return (f"{rule} (delta_0/tau_0); N = {self.n_blocks}, k_c = {p['k_c']:g}, "
                f"k_p = {self.settings.parameters['k_d']:g}, dt = {self.settings.parameters['dt']:g}")

    # ------------------------------------------------------------------ state
    def get_state(self) -> dict:
        """Everything needed to continue the run bit for bit, as plain values (the catalogue
        file is not part of it: it records events as they close)."""
        self._require_started()
        return {"n_blocks": self.n_blocks, "periodic": self.periodic, "energy_balance": self.energy_balance,
                "clusters": self.clusters, "jump_sticks": self.jump_sticks, "jumped_steps": self.jumped_steps,
                "jump_backoff": self.jump_backoff,
                "time": self.time, "energy_at_start": self.energy_at_start, "events": list(self.events),
                "chain_parameters": dict(self.chain_parameters), "settings": self.settings.to_dict(),
                **{name: getattr(self, name).tolist() for name in ("Y", "PRM", "cnt", "drv", "chn", "evt", "scratch",
                                                                   "clu")}}

    def set_state(self, state: dict) -> None:
        try:
            arrays = {name: np.ascontiguousarray(state[name], dtype=np.int64 if name == "cnt" else float)
                      for name in ("Y", "PRM", "cnt", "drv", "chn", "evt", "scratch", "clu")}
            n_blocks = int(state["n_blocks"])
        except (KeyError, TypeError, ValueError) as exc:
            raise ModelError(f"not a valid chain state: {exc}") from None
        if n_blocks != self.n_blocks or arrays["Y"].shape != (n_blocks, L.N_Y):
            raise ModelError(f"not a valid chain state: it holds {n_blocks} blocks, this chain {self.n_blocks}")
        if arrays["chn"].shape != (K.N_CHN,) or arrays["scratch"].shape != (n_blocks, K.N_SCRATCH):
            raise ModelError("not a valid chain state: its arrays have another layout (saved by another version "
                             "of the chain)")
        self.settings = Settings.from_dict(state["settings"], self.settings.model)
        self.chain_parameters = dict(state["chain_parameters"])
        self.periodic, self.energy_balance = bool(state["periodic"]), bool(state["energy_balance"])
        self.clusters = bool(state["clusters"])
        self.jump_sticks, self.jumped_steps = bool(state.get("jump_sticks", False)), int(state.get("jumped_steps", 0))
        self.jump_backoff = int(state.get("jump_backoff", 0))
        self._modes = None
        for name, value in arrays.items():
            setattr(self, name, value)
        self.rows = self._catalogue_rows()
        self.events = [tuple(e) for e in state["events"]]
        self.time, self.energy_at_start = float(state["time"]), float(state["energy_at_start"])
        self.started = True
