# The default CUDA architectures: machine code for every current GPU a robot
# or a cloud carries, as far as this nvcc can build it, and PTX of the lowest
# so that any later GPU can JIT-compile the kernels.
#
#   sm_75  T4 (the commonest cloud inference GPU), RTX 20
#   sm_80  A100            sm_86  A10, RTX 30          sm_87  Jetson AGX Orin, Orin NX, Orin Nano
#   sm_89  L4, RTX 40      sm_90  H100, H200           sm_100 B200
#   sm_110 Jetson Thor     sm_120 RTX 50               sm_121 DGX Spark
#
# Override with -DCMAKE_CUDA_ARCHITECTURES=... (e.g. "native" for the GPU of
# the build machine only, or "75-virtual" for PTX alone).
set(VASCO_WANTED_CUDA_ARCHS 75 80 86 87 89 90 100 110 120 121)

function(vasco_default_cuda_architectures nvcc out)
  execute_process(COMMAND ${nvcc} --list-gpu-code OUTPUT_VARIABLE codes ERROR_QUIET RESULT_VARIABLE rc)
  set(have "")
  if(rc EQUAL 0)
    string(REGEX MATCHALL "sm_[0-9]+" codes "${codes}")
    foreach(c ${codes})
      string(REPLACE "sm_" "" n "${c}")
      list(APPEND have ${n})
    endforeach()
  endif()
  set(archs "")
  set(lowest "")
  foreach(a ${VASCO_WANTED_CUDA_ARCHS})
    if(a IN_LIST have)
      list(APPEND archs "${a}-real")
      if(lowest STREQUAL "")
        set(lowest ${a})
      endif()
    endif()
  endforeach()
  if(lowest STREQUAL "")
    # An nvcc that cannot list its architectures: the kernels' minimum, as PTX.
    set(archs "75-virtual")
  else()
    list(APPEND archs "${lowest}-virtual")
  endif()
  set(${out} "${archs}" PARENT_SCOPE)
endfunction()
