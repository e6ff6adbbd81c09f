% Read an identification's results into MATLAB or Octave. First, in a shell:
%     thermofriction identify my-stage --method model-i --json fit.mat -o fitted.toml
if ~exist('fit_file', 'var')
  fit_file = 'fit.mat';
end
fit = thermofriction.read_fit(fit_file);
fprintf('method %s, RMSE %.3g %s, %d parameters\n', fit.method, fit.rmse_offset_removed, fit.unit, ...
        numel(fit.parameters.name));
for k = 1:numel(fit.parameters.name)
  fprintf('  %-12s %12.5g +- %.2g %s\n', fit.parameters.name{k}, fit.parameters.value(k), ...
          fit.parameters.stderr(k), fit.parameters.unit{k});
end
