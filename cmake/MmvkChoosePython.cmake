# Chooses the Python interpreter the module (python/) is built for and its
# tests run with, before any find_package(Python3).
#
# The module needs numpy at run time, and .ci/install-deps installs numpy,
# pytest and the headers for Debian's own /usr/bin/python3. A machine may
# put another python3 first on PATH (pyenv, a bare interpreter) that has no
# numpy: building for it gives a module that cannot be imported with numpy
# and tests that cannot run. So when the first python3 on PATH lacks numpy
# and Debian's has it, Debian's is chosen, and configure says so. A virtual
# environment or interpreter with numpy is kept, and -DPython3_EXECUTABLE
# always wins.
if(NOT DEFINED Python3_EXECUTABLE)
  find_program(_mmvk_path_python NAMES python3 NO_CACHE)
  set(_mmvk_system_python /usr/bin/python3)
  if(_mmvk_path_python AND EXISTS ${_mmvk_system_python})
    execute_process(COMMAND ${_mmvk_path_python} -c "import numpy"
                    RESULT_VARIABLE _mmvk_path_numpy OUTPUT_QUIET ERROR_QUIET)
    if(NOT _mmvk_path_numpy EQUAL 0)
      execute_process(COMMAND ${_mmvk_system_python} -c "import numpy"
                      RESULT_VARIABLE _mmvk_system_numpy OUTPUT_QUIET ERROR_QUIET)
      if(_mmvk_system_numpy EQUAL 0)
        message(STATUS "mmvk: ${_mmvk_path_python} has no numpy; the Python module is built for "
                       "${_mmvk_system_python} (-DPython3_EXECUTABLE=... chooses another)")
        set(Python3_EXECUTABLE ${_mmvk_system_python} CACHE FILEPATH
            "The Python interpreter the mmvk module is built for")
      endif()
    endif()
  endif()
endif()
