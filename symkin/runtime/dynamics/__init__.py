"""Forward dynamics: how a mechanism moves under its forces (issue 37's runtime side).

- model: what the integrator needs from a mechanism (:class:`model.Model`: Φ, Φ_q, Φ_t, Γ,
  M, Q - h, V, Q_nc, the loads) and :class:`model.MotionKernel`, what ``symkin.compile``
  returns for a mechanism its forces move;
- equations: the accelerations and multipliers of one state, [M Φ_qᵀ; Φ_q 0][q̈; λ] =
  [Q - h; Γ];
- initial: the assembled position at t0 and the consistent initial velocity (least kinetic
  energy in the freedoms the given components leave open);
- passages: singular configurations passed through between steps (found, reported);
- integrator: an embedded Runge-Kutta pair (Dormand-Prince 5(4)) with error control and a
  projection onto Φ = 0, Φ_q q̇ = -Φ_t after every accepted step;
- run: ``symkin.solve`` of such a mechanism over a time grid, the Trajectory with efforts,
  reactions and the energy balance.

Imports NumPy only (and the runtime's shared pieces), like the rest of the runtime.
"""
