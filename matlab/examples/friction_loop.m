% The model's friction stepped in a control loop, one control period at a time, as a controller does
% (the C core's real-time API): feed-forward from the reference velocity, and the observer of
% Canudas de Wit et al. fed the measured velocity and position error. First, in a shell:
%     thermofriction fmu li2009-model-i -o li2009-model-i.fmu
if ~exist('fmu_file', 'var')
  fmu_file = 'li2009-model-i.fmu';
end
model = thermofriction.load_model(fmu_file);
dt = 1e-4;                                 % 10 kHz control loop
t = (0:dt:0.05)';
v_ref = 2e-3 * sin(2 * pi * 20 * t);       % [m/s]
T = 35.7;                                  % [degC] the temperature sensor
F = zeros(size(t));
for n = 1:numel(t)                         % one call per period, as in a controller
  F(n) = thermofriction.friction_step(model, v_ref(n), T, dt);
end
fprintf('feed-forward friction: %.4f to %.4f N\n', min(F), max(F));
thermofriction.reset_friction(model);
F_whole = thermofriction.friction_step(model, v_ref, T, dt);   % the same in one call
fprintf('one call per period and one call for all: largest difference %g N\n', max(abs(F_whole - F)));
thermofriction.reset_friction(model);
e = 1e-7 * ones(size(t));                  % a position error [m]
F_obs = thermofriction.observer_step(model, v_ref, e, 1000, T, dt);
fprintf('observer (gain 1000 1/s): %.4f to %.4f N\n', min(F_obs), max(F_obs));
thermofriction.close_model(model);
