function res = simulate(model, t, drive, temperature, rtol)
%SIMULATE  Simulate a model driven by sampled inputs.
%   res = thermofriction.simulate(model, t, drive, temperature) simulates the model opened by
%   thermofriction.load_model over the times t [s] (increasing), the drive (the plant's input: a
%   voltage [V] for the stick-slip actuator, a force [N] for a mass, the displacement [m] for
%   prescribed motion) and the temperature [degC] (the ambient temperature with a heat model) given at
%   those times, each one value per sample or one value held. Between two samples the inputs follow
%   the straight line between them. A model without a temperature input takes [] as temperature.
%
%   res = thermofriction.simulate(..., rtol) sets the integrator's relative tolerance (default 1e-6).
%
%   This is the FMU's co-simulation with t as its communication points: the C core's adaptive
%   integrator (or the FMU's fixed-step real-time solver) between samples, so the result is the FMU's
%   bit for bit, and within the integrator's tolerance of the Python package's simulate().
%
%   res is a struct of column vectors (SI units, degC): time, displacement, velocity, friction_force,
%   temperature, stage_displacement (NaN where the plant has no such output).
%
%   Example:
%     t = (0:1e-4:0.02)';
%     res = thermofriction.simulate(model, t, 50 * sin(2*pi*100*t), 35.7);
%     plot(res.time, res.displacement)
%
%   See also thermofriction.load_model, thermofriction.friction_step.
if nargin < 4
  error('thermofriction:argument', 'simulate: give model, t, drive and temperature ([] without a temperature input)');
end
if nargin < 5
  rtol = 1e-6;
end
if model.temperature_input && isempty(temperature)
  error('thermofriction:argument', 'simulate: this model takes a temperature [degC]: give one value or one per sample');
end
if ~model.temperature_input && ~isempty(temperature)
  error('thermofriction:argument', ['simulate: this model has no temperature input (no thermal extension or ' ...
        'heat model): give [] as the temperature']);
end
Y = thermofriction_mex('simulate', model.handle, double(t(:)), double(drive(:)), double(temperature(:)), double(rtol));
res = struct('time', double(t(:)), 'displacement', Y(:, 1), 'velocity', Y(:, 2), 'friction_force', Y(:, 3), ...
             'temperature', Y(:, 4), 'stage_displacement', Y(:, 5));
end
