# Runs PROGRAM under MPIEXEC with RANKS ranks and ARGS; passes only if it exits non-zero and its
# output matches EXPECT. (CTest alone can check one or the other, not both.)
string(REPLACE ";" " " shown "${ARGS}")
separate_arguments(launcher UNIX_COMMAND "${MPIEXEC}")
execute_process(COMMAND ${launcher} -n ${RANKS} ${PROGRAM} ${ARGS}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(code EQUAL 0)
  message(FATAL_ERROR "mini_md ${shown} exited 0; a failure was expected")
endif()
if(NOT "${out}${err}" MATCHES "${EXPECT}")
  message(FATAL_ERROR "mini_md ${shown} failed without the expected message '${EXPECT}'")
endif()
