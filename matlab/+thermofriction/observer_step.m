function F = observer_step(model, v, e, k, T, dt, load)
%OBSERVER_STEP  Observer-based friction estimate in a control loop (the real-time C API).
%   F = thermofriction.observer_step(model, v, e, k, T, dt) advances the friction observer of
%   Canudas de Wit et al. (1995) on the model opened by thermofriction.load_model by dt [s] per
%   element of v and returns the estimated friction force F [N]: v the measured velocity [m/s],
%   e = x - x_ref the position error [m], k >= 0 the observer gain [1/s] (k = 0: the model's own
%   friction, as thermofriction.friction_step), T the temperature [degC]. e, k, T and dt: one value
%   or one per element of v. It shares its state with thermofriction.friction_step.
%
%   F = thermofriction.observer_step(model, v, e, k, T, dt, load) steps at the load [N or N m]: one
%   value or one per element of v, read by the model's laws of the load (required by a model with
%   one; a model without ignores it).
%
%   The step is the C core's tf_observer_step (control.h), defined for the models with a bristle
%   deflection (LuGre, Dahl, elasto-plastic); other friction models are refused.
%
%   See also thermofriction.friction_step, thermofriction.reset_friction.
if nargin < 7
  F = thermofriction_mex('observer', model.handle, double(v), double(e), double(k), double(T), double(dt));
else
  F = thermofriction_mex('observer', model.handle, double(v), double(e), double(k), double(T), double(dt), ...
                         double(load));
end
end
