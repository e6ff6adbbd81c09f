% Simulate a thermofriction model in MATLAB or Octave: the paper's stick-slip actuator (Model I) driven
% by a sine voltage at two temperatures. First, in a shell:
%     thermofriction fmu li2009-model-i -o li2009-model-i.fmu
% then, in MATLAB or Octave, with matlab/ on the path and the MEX built (thermofriction.build()):
%     run simulate_model
if ~exist('fmu_file', 'var')
  fmu_file = 'li2009-model-i.fmu';
end
model = thermofriction.load_model(fmu_file);
t = (0:1e-5:0.02)';                 % 2 cycles of 100 Hz, sampled at 100 kHz
drive = 50 * sin(2 * pi * 100 * t);  % [V]
for T = [30.8, 41.5]
  res = thermofriction.simulate(model, t, drive, T);
  fprintf('T = %4.1f C: displacement after 2 cycles %8.3f um, peak friction force %.4f N\n', T, ...
          1e6 * res.displacement(end), max(abs(res.friction_force)));
end
thermofriction.close_model(model);
