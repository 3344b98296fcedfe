"""``adaptive`` (id 4, every model and reading): error-controlled, stiff-stable steps with located events.

On model A, whose every regime is linear, the registry hands a run over to the exact flows
of ``event_driven`` instead (option ``exact_flows``, on by default; where event_driven
cannot run the reading or the parameters these steps run).  What follows is the method
of models B and C, and of model A with that option off.

The package is split as scipy's ``_ivp`` is, one module a part:

* ``driver``: the call's loop over named steps, and the ``advance``/``observe`` kernels;
* ``methods``: the two embedded pairs under one error control and the choice between them;
* ``dop853``: Dormand & Prince's explicit pair of order 8 (where the motion is not stiff);
* ``rodas4``: the stiff-stable Rosenbrock method of order 4 (where it is);
* ``regimes``: the right-hand side of each contact regime, its event values, the plate's clock;
* ``events``: event location (one root finder for the interpolant and the full steps);
* ``jumps``: the stroboscopic jumps across the periods of a held block on a vibrating plate;
* ``workspace``: the scratch arrays the steps share.

The contract (``integrators/__init__.py``) as this integrator keeps it:

* Methods.  DOP853 where the motion is not stiff (ringing contact and friction springs,
  flights, slips: the tolerance limits the step), RODAS4 where DOP853's steps would meet
  its stability bound (a long stick whose ringing has died); the hand-over both ways is
  ``methods``'s.  The ``jacobians`` counter counts RODAS4's linearisations.  A step is
  accepted when the weighted RMS of its embedded error over the state components is
  <= 1 (weights atol + rtol max(|y0|, |y1|)); the friction law's state theta is a sixth
  component, counted where the law moves it (rate-and-state: ``regimes``).
* Step caps.  While the plate moves harmonically a step spans at most CYCLE_FRACTION of
  its period, so no landing or grazing contact is stepped over unseen; a long stick
  without vibration is crossed in steps growing sixfold each.  The one exception is a
  flight above the plate's reach (the block higher than the plate at its highest, the
  external input at rest): no phase of the plate can meet the block there, so a step may
  span up to REACH_SHARE of the time a quadratic model of that clearance gives until the
  block could be within the reach again.  Such a step is kept only if the clearance stays
  positive at its interpolant's samples and its end; else it is retaken at the cap, which
  then holds until the flight's landing.
* Dense output.  Each RODAS4 step carries its third-order interpolant, each DOP853 step the
  cubic Hermite interpolant of its end values and rates; both serve only to sample the
  event values, the switches being refined on full steps (``events``).
* Regimes and events: the table in ``regimes``.  A reset that follows the previous one
  within CASCADE_GAP ends in the cascade regime (the dashpot pulling the block out makes
  resets accumulate at the zero of N; the spring is held at zero from there until N has
  crossed zero, the cascade's limit).  The friction rule is applied at each located
  switch, not at a step's end.
* Readings (docs/physics.md; bits of the run constant ``kind``).  The tangent frame moves
  the position slots at ``position_rates`` (dx/dt = u cos a, d zeta/dt = w) and phi
  integrates (dx/dt - V_d)^2 with that dx/dt; its contact, forces and energy rates are
  ``dynamics``'s.  The Coulomb bound's N is ``coulomb_bound`` of the continued contact
  force, at the block's x and the time of the value (the applied load depends on both, so
  every event value is evaluated at its own time).  Free flight: each regime keeps one
  frame on both sides of delta = 0 -- the contact regimes the surface's
  (``dynamics.surface_contact``), the flight regime the fixed axes -- and the frame
  switches only at the located event, with the regime (a switch of frame inside a step
  would be a kink that the Jacobian, the error estimate and the event search straddle).
  The tangent frame with free flight is refused for every integrator (docs/physics.md Sec. 6).
* Stroboscopic jumps (``jumps``): while the block is held (regime loaded) on a plate that
  moves harmonically, whole plate periods are taken many at a time through the period
  map's affine model, with error control per period crossed and a hand-back to resolved
  steps before any switch (``max_jump`` bounds a jump, below STROBE_MIN it turns them off;
  ``cnt[C_JUMPED]`` counts the periods crossed).
* Grid.  As ``event_driven``: dt only sets the grid on which the state is stored; a call
  integrates from t0 + n dt to t0 + (n + n_steps) dt.  Splits agree to the tolerances
  (the step sequence depends on where a run stops), not bit for bit.
* Failure: a negative status (below) with the arrays untouched.

Measurements of this integrator are in docs/benchmarks.md.
"""
from .dop853 import EXPLICIT_A, EXPLICIT_B, EXPLICIT_C, EXPLICIT_E3, EXPLICIT_E5  # noqa: F401
from .driver import (MAX_IMMEDIATE, MAX_STEPS, NON_FINITE, OK, STEP_TOO_SMALL, TOO_MANY_EVENTS,  # noqa: F401
                     TOO_MANY_STEPS, advance, observe)
from .workspace import EXPLICIT_STAGES  # noqa: F401
