# CMake toolchain file: cross-compile for Windows x86-64 with the MinGW-w64 toolchain
# (Debian: gcc-mingw-w64-x86-64). Used for the FMU's win64 binary (core/CMakeLists.txt, TF_BUILD_FMU).
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(TF_MINGW_PREFIX x86_64-w64-mingw32)
set(CMAKE_C_COMPILER ${TF_MINGW_PREFIX}-gcc)
set(CMAKE_RC_COMPILER ${TF_MINGW_PREFIX}-windres)
set(CMAKE_FIND_ROOT_PATH /usr/${TF_MINGW_PREFIX})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
