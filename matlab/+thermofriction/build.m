function mexfile = build()
%BUILD  Compile the thermofriction MEX gateway from the C sources.
%   thermofriction.build() compiles matlab/thermofriction_mex.c with the C core (core/src/*.c) and
%   the FMU's model logic (core/fmu/fmu_common.c) into matlab/thermofriction_mex.<mexext>, with
%   Octave's mkoctfile --mex or MATLAB's mex (a C compiler set up with "mex -setup C"). Run it once
%   from the repository (the sources are found relative to this file) after adding matlab/ to the path.
%
%   mexfile = thermofriction.build() returns the path of the compiled MEX file.
%
%   See also thermofriction.load_model.
here = fileparts(fileparts(mfilename('fullpath')));   % matlab/
root = fileparts(here);
core = dir(fullfile(root, 'core', 'src', '*.c'));
sources = [{fullfile(here, 'thermofriction_mex.c'), fullfile(root, 'core', 'fmu', 'fmu_common.c')}, ...
           cellfun(@(n) fullfile(root, 'core', 'src', n), {core.name}, 'UniformOutput', false)];
includes = {['-I' fullfile(root, 'core', 'include')], ['-I' fullfile(root, 'core', 'fmu')]};
objects = tempname();   % the object files, away from the sources
mkdir(objects);
back = cd(objects);
cleanup = onCleanup(@() finish(back, objects));
if exist('OCTAVE_VERSION', 'builtin')
  old = getenv('CFLAGS');
  setenv('CFLAGS', '-std=c99 -O2 -fPIC');
  [output, status] = mkoctfile('--mex', '-o', fullfile(here, 'thermofriction_mex'), includes{:}, sources{:});
  setenv('CFLAGS', old);
  if status ~= 0
    error('thermofriction:build', 'thermofriction.build: mkoctfile failed:\n%s', output);
  end
else
  mex('-outdir', here, '-output', 'thermofriction_mex', 'CFLAGS=$CFLAGS -std=c99', includes{:}, sources{:});
end
mexfile = fullfile(here, ['thermofriction_mex.' mexext()]);
end

function finish(back, objects)
cd(back);
if exist('OCTAVE_VERSION', 'builtin')
  confirm_recursive_rmdir(false, 'local');
end
rmdir(objects, 's');
end
