# Writes OUTPUT (a header defining RAILCRASH_COMMIT) with the commit of the source checkout at
# SOURCE_DIR: "abc1234def56" or "abc1234def56-dirty" when tracked files differ from it, "" when the
# sources are not a git checkout (a release tarball) or git is missing. Run at every build (the
# target railcrash_build_commit); the header is rewritten only when the text changes, so only
# src/core/version.cpp is compiled again after a commit.
set(commit "")
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(COMMAND ${GIT_EXECUTABLE} -C ${SOURCE_DIR} rev-parse --short=12 HEAD
                  OUTPUT_VARIABLE head RESULT_VARIABLE failed OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(NOT failed AND head)
    set(commit "${head}")
    # (status, not diff-index: it refreshes the index, so a file touched but unchanged is clean)
    execute_process(COMMAND ${GIT_EXECUTABLE} -C ${SOURCE_DIR} status --porcelain --untracked-files=no
                    OUTPUT_VARIABLE changes RESULT_VARIABLE failed_status ERROR_QUIET)
    if(NOT failed_status AND NOT changes STREQUAL "")
      set(commit "${commit}-dirty")
    endif()
  endif()
endif()
set(text "// Written by cmake/build_commit.cmake at build time.\n#define RAILCRASH_COMMIT \"${commit}\"\n")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
else()
  set(old "")
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUTPUT}" "${text}")
endif()
