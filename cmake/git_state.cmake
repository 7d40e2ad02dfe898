# Writes OUT, a header with the source tree's git commit and whether it has
# uncommitted changes (BOUNCECHECK_GIT_COMMIT, BOUNCECHECK_GIT_DIRTY), for
# reports/provenance.cpp. Run at every build (the bouncecheck_git_state
# target), not only at configure time, so a build after a commit reports
# that commit; the file is rewritten only when its text changes, so such a
# build recompiles one file. Without git or a checkout: no commit, clean.
#   cmake -DSOURCE_DIR=... -DGIT_EXECUTABLE=... -DOUT=... -P git_state.cmake
set(commit "")
set(dirty 0)
if(GIT_EXECUTABLE AND EXISTS "${SOURCE_DIR}/.git")
  execute_process(COMMAND "${GIT_EXECUTABLE}" rev-parse HEAD WORKING_DIRECTORY "${SOURCE_DIR}"
                  OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  execute_process(COMMAND "${GIT_EXECUTABLE}" status --porcelain --untracked-files=no
                  WORKING_DIRECTORY "${SOURCE_DIR}" OUTPUT_VARIABLE changes ERROR_QUIET)
  if(changes)
    set(dirty 1)
  endif()
endif()
set(text "// Written by cmake/git_state.cmake at build time.\n#define BOUNCECHECK_GIT_COMMIT \"${commit}\"\n#define BOUNCECHECK_GIT_DIRTY ${dirty}\n")
set(old "")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUT}" "${text}")
endif()
