"""Index layout of the arrays the numba kernels share.

The dynamic state lives in a few flat arrays so that it can be saved, restored and
serialised whole (FMU state) and handed to compiled kernels without conversion.
"""

# Physical parameters, float64 array ``prm``: the slots every variant shares, then the
# slots of the variants' own parameters (corrugation, confining force, ...), handed out
# by ``slot`` in the order the variants are registered.
COMMON_PRM_NAMES = ("m", "g", "k_n", "k_t", "gamma_n", "gamma_t", "mu_s", "k_d", "V_d", "rtol", "atol", "max_jump")
P_M, P_G, P_KN, P_KT, P_GN, P_GT, P_MUS, P_KD, P_VD, P_RTOL, P_ATOL, P_MAX_JUMP = range(len(COMMON_PRM_NAMES))
N_PRM = 32  # capacity: common slots + every registered variant's own parameters
_PRM_SLOTS = {name: i for i, name in enumerate(COMMON_PRM_NAMES)}


def slot(name: str) -> int:
    """The ``prm`` index of a parameter; a variant's own parameter gets the next free slot
    the first time it is named (compiled kernels read it as a constant)."""
    if name not in _PRM_SLOTS:
        if len(_PRM_SLOTS) >= N_PRM:
            raise RuntimeError(f"no free parameter slot for {name!r}: raise layout.N_PRM")
        _PRM_SLOTS[name] = len(_PRM_SLOTS)
    return _PRM_SLOTS[name]


def prm_slots() -> dict[str, int]:
    return dict(_PRM_SLOTS)


# Continuous state, float64 array ``y``: block position and velocity, the tangential
# spring's displacement F (Cundall-Strack), the integral of (vx - V_d)^2 and the
# compensation term of its Kahan sum (the integral runs over up to 1e12 steps), and the
# energy balance: work done on the block, energy dissipated (dashpots and resets), energy
# stored in the normal spring, and the stored energy at the start; the friction law's
# state (its ``rule`` says what it holds: whether the block slides under a kinetic bound,
# the rate-and-state variable theta, or nothing).
Y_X, Y_Z, Y_VX, Y_VZ, Y_F, Y_PHI, Y_PHI_C, Y_WORK, Y_DISSIPATED, Y_E_NORMAL, Y_E_START, Y_FRICTION_STATE = range(12)
N_Y = 12

# Integer counters, int64 array ``cnt``: internal steps taken since the start (time is
# t0 + n dt, never accumulated), Coulomb resets, the step at which the drive phase was
# last re-anchored (omega is tunable; the phase stays continuous when it changes), and
# the cost counters of the integrators: located events (contact, detachment, reset),
# rejected trial steps, and of an error-controlled integrator its accepted internal
# steps and Jacobian evaluations, and the plate periods crossed by stroboscopic jumps or
# skipped on a periodic orbit.
C_STEP, C_SLIPS, C_PHASE_STEP, C_EVENTS, C_REJECTED, C_ACCEPTED, C_JACOBIANS, C_JUMPED = range(8)
N_CNT = 8

# Clock and plate drive, float64 array ``drv``: start time, step, the harmonic drive's
# vertical amplitude, angular frequency, drive phase at C_PHASE_STEP, and the external
# plate input (height, velocity, acceleration) with the communication time at which it
# was set; then the horizontal parts of an oblique plate (``laws.plate_oblique``): the
# drive's horizontal amplitude and the external input's horizontal position, velocity
# and acceleration (zero under the vertical plate law).
D_T0, D_DT, D_AMP, D_OMEGA, D_PHASE, D_EXT_Z, D_EXT_V, D_EXT_A, D_EXT_T = range(9)
D_AMP_X, D_EXT_X, D_EXT_VX, D_EXT_AX = range(9, 13)
N_DRV = 13

# One observation, float64 array ``obs`` that every integrator's observe kernel fills:
# the state at the requested time, the contact quantities there, the quadratures, the
# Coulomb resets so far, and the contact state and friction force as the scheme sees
# them (a reduced scene has its own rigid contact and Coulomb force); then the plate's
# horizontal position and velocity, which O_X and O_VX include (the kernels integrate
# an oblique plate's run in the plate's frame; 0 under the vertical plate law).
(O_X, O_Z, O_VX, O_VZ, O_F, O_PENETRATION, O_NORMAL, O_COS, O_PHI, O_SLIPS, O_WORK, O_DISSIPATED,
 O_E_NORMAL, O_T, O_CONTACT, O_FRICTION, O_PLATE_X, O_PLATE_VX) = range(18)
N_OBS = 18
