cmake_minimum_required(VERSION 3.25)
# Runs SCRIPT through the sqlite3 shell with the extension at EXTENSION loaded and compares the
# output with EXPECTED.
file(READ ${SCRIPT} script)
string(REPLACE "@EXTENSION@" "${EXTENSION}" script "${script}")
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/shell_session.run.sql "${script}")
execute_process(COMMAND ${SHELL} -batch :memory:
  INPUT_FILE ${CMAKE_CURRENT_BINARY_DIR}/shell_session.run.sql
  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
file(READ ${EXPECTED} expected)
if(NOT rc EQUAL 0 OR NOT out STREQUAL expected)
  message(FATAL_ERROR "sqlite3 shell session differs (exit ${rc}):\n--- got\n${out}${err}\n--- expected\n${expected}")
endif()
