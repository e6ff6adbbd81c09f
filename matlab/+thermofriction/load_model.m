function model = load_model(file)
%LOAD_MODEL  Open a thermofriction model exported as an FMU.
%   model = thermofriction.load_model(FILE) opens FILE, an FMU written by the command line's
%   "thermofriction fmu MODEL -o FILE.fmu" (any model file or preset; FMI 2 or 3, adaptive or
%   realtime solver), or the folder it was unzipped into. The C core reads the model from the FMU's
%   resources/model.tfm with the same reader as the FMU itself, so what MATLAB computes is what the
%   FMU computes in Simulink.
%
%   model is a struct: name, file, folder (the unzipped FMU), guid, temperature_input (true when the
%   model takes a temperature: a thermal extension, or with a heat model the ambient temperature),
%   parameters (a struct of the FMU's parameters' start values, by their names with '.' as '_'),
%   handle (the MEX's; close it with thermofriction.close_model).
%
%   Example:
%     % in a shell: thermofriction fmu li2009-model-i -o li2009.fmu
%     model = thermofriction.load_model('li2009.fmu');
%     res = thermofriction.simulate(model, t, drive, 35.7);
%     thermofriction.close_model(model);
%
%   See also thermofriction.simulate, thermofriction.friction_step, thermofriction.close_model.
if ~ischar(file) || isempty(file)
  error('thermofriction:argument', 'load_model: FILE must be a file name (an .fmu or its unzipped folder)');
end
if exist(file, 'file') ~= 2 && exist(file, 'dir') ~= 7
  error('thermofriction:argument', 'load_model: %s: no such file or folder', file);
end
folder = file;
if exist(file, 'dir') ~= 7
  folder = tempname();
  try
    unzip(file, folder);
  catch err
    error('thermofriction:argument', 'load_model: %s: not an FMU (a zip archive): %s', file, err.message);
  end
end
resources = fullfile(folder, 'resources');
tfm = fullfile(resources, 'model.tfm');
description = fullfile(folder, 'modelDescription.xml');
if exist(tfm, 'file') ~= 2 || exist(description, 'file') ~= 2
  error('thermofriction:argument', ['load_model: %s: not an FMU of thermofriction (no resources/model.tfm ' ...
        'or modelDescription.xml); write one with "thermofriction fmu MODEL -o FILE.fmu"'], file);
end
text = fileread(tfm);
guid = regexp(text, '(?m)^guid\s+(\S+)', 'tokens', 'once');
if isempty(guid)
  error('thermofriction:argument', 'load_model: %s: resources/model.tfm has no guid line', file);
end
xml = fileread(description);
model = struct();
model.name = attribute(xml, 'modelName');
model.file = file;
model.folder = folder;
model.guid = guid{1};
model.temperature_input = any(~cellfun(@isempty, regexp(text, {'(?m)^temperature_input\s+1', '(?m)^heat\s+1'}, 'once')));
model.parameters = parameters(xml);
model.handle = thermofriction_mex('open', resources, model.guid);
end

function value = attribute(xml, name)
value = regexp(xml, [name '="([^"]*)"'], 'tokens', 'once');
if isempty(value), value = ''; else, value = value{1}; end
end

% The FMU's parameters and their start values: <ScalarVariable name=... causality="parameter"> <Real start=...>
% (FMI 2) or <Float64 name=... causality="parameter" start=...> (FMI 3).
function p = parameters(xml)
p = struct();
elements = regexp(xml, '<(?:ScalarVariable|Float64)\s[^>]*causality="parameter"[^>]*>(?:\s*<Real[^>]*>)?', 'match');
for i = 1:numel(elements)
  name = attribute(elements{i}, 'name');
  start = attribute(elements{i}, 'start');
  if ~isempty(name) && ~isempty(start)
    p.(regexprep(name, '[^A-Za-z0-9_]', '_')) = str2double(start);
  end
end
end
