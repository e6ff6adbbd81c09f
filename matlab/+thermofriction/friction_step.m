function F = friction_step(model, v, T, dt, load)
%FRICTION_STEP  Step the model's friction in a control loop (the real-time C API).
%   F = thermofriction.friction_step(model, v, T, dt) advances the friction of the model opened by
%   thermofriction.load_model by one control period dt [s] per element of v, at sliding velocity
%   v [m/s] held over the period and temperature T [degC] (ignored without a thermal extension), and
%   returns the friction force F [N] after each step (the size of v). T and dt: one value, or one per
%   element of v. The internal states (the bristle deflection) carry over from call to call, so
%   calling it once per period in a loop and once with a whole vector give the same forces.
%
%   F = thermofriction.friction_step(model, v, T, dt, load) steps at the load [N, or N m for a
%   rotary joint]: one value or one per element of v, read by the model's laws of the load (required
%   by a model with one; a model without ignores it).
%
%   The step is the C core's tf_rt_step (realtime.h): exponential Euler, exact for the bristle
%   models while v is constant, stable at any dt. A refused step (a parameter out of its domain at
%   T and the load, a non-finite input, no load for a law of the load) is an error naming the step;
%   the steps before it were taken.
%
%   Example (feed-forward compensation at 10 kHz):
%     for n = 1:N
%       u(n) = pid_output(n) + thermofriction.friction_step(model, v_ref(n), T_sensor, 1e-4);
%     end
%
%   See also thermofriction.observer_step, thermofriction.reset_friction.
if nargin < 5
  F = thermofriction_mex('friction', model.handle, double(v), double(T), double(dt));
else
  F = thermofriction_mex('friction', model.handle, double(v), double(T), double(dt), double(load));
end
end
