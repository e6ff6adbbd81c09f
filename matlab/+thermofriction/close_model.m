function close_model(model)
%CLOSE_MODEL  Close a model opened by thermofriction.load_model.
%   thermofriction.close_model(model) frees the model's C instance and removes the folder an FMU was
%   unzipped into. The model's handle is no longer valid afterwards.
%
%   See also thermofriction.load_model.
thermofriction_mex('close', model.handle);
if ~strcmp(model.folder, model.file) && exist(model.folder, 'dir') == 7
  if exist('OCTAVE_VERSION', 'builtin')
    confirm_recursive_rmdir(false, 'local');
  end
  rmdir(model.folder, 's');
end
end
