function reset_friction(model)
%RESET_FRICTION  Bring the friction loop's internal states to rest.
%   thermofriction.reset_friction(model) sets the internal states that thermofriction.friction_step
%   and thermofriction.observer_step carry (the bristle deflection) to rest (tf_rt_reset).
%
%   See also thermofriction.friction_step, thermofriction.observer_step.
thermofriction_mex('reset', model.handle);
end
