function fit = read_fit(file)
%READ_FIT  Read identification results written by the Python package.
%   fit = thermofriction.read_fit(FILE) reads the results of "thermofriction identify ... --json FILE"
%   (or fit.to_json / fit.to_mat in Python):
%     - FILE.mat (recommended): the package's MATLAB results (docs/formats.md, "Results in MATLAB files"),
%       read with load: fit.parameters.name{k} ('sigma0.a'), fit.parameters.value(k),
%       fit.parameters.stderr(k), fit.parameters.unit{k}; fit.experiments.file{k}, ...; NaN and Inf as
%       numbers;
%     - FILE.json: the results JSON read with jsondecode (MATLAB R2016b+, Octave 7+): the same keys, but
%       a parameter's name becomes a valid field name (fit.parameters.sigma0_a.value) and JSON's
%       "nan" and "inf" stay text.
%   The keys are those of docs/formats.md, "Results JSON": method, success, parameters, cost,
%   rmse_offset_removed, aicc, experiments, warnings, model (the fitted model's tables), ...
%
%   Example:
%     % in a shell: thermofriction identify my-stage --method model-i --json fit.mat -o fitted.toml
%     fit = thermofriction.read_fit('fit.mat');
%     [fit.parameters.name, num2cell(fit.parameters.value), num2cell(fit.parameters.stderr)]
%
%   See also thermofriction.load_model.
if ~ischar(file) || exist(file, 'file') ~= 2
  error('thermofriction:argument', 'read_fit: %s: no such file', char(file));
end
[~, ~, ext] = fileparts(file);
switch lower(ext)
  case '.mat'
    fit = load(file);
  case '.json'
    try
      fit = jsondecode(fileread(file));
    catch err
      error('thermofriction:argument', 'read_fit: %s: not a results JSON: %s', file, err.message);
    end
  otherwise
    error('thermofriction:argument', 'read_fit: %s: give the .mat or .json that identify --json wrote', file);
end
if ~isstruct(fit) || ~isfield(fit, 'method') || ~isfield(fit, 'parameters')
  error('thermofriction:argument', 'read_fit: %s: not identification results (no method or parameters)', file);
end
end
