# Checks that the cargo colcon will run is new enough for the crate: Ubuntu 24.04's
# packaged cargo (1.75) is older than the crate's rust-version, and its own error
# ("package requires rustc 1.85") comes only after a long dependency download. Reads
# rust-version from Cargo.toml, so the two cannot disagree. Needs CARGO_EXECUTABLE and
# CARGO_MANIFEST; usable on its own: cmake -DCARGO_EXECUTABLE=cargo
# -DCARGO_MANIFEST=Cargo.toml -P cmake/cargo_toolchain.cmake
file(STRINGS "${CARGO_MANIFEST}" rust_version_line REGEX "^rust-version *= *\"[0-9.]+\"")
string(REGEX MATCH "[0-9]+\\.[0-9]+(\\.[0-9]+)?" RUST_VERSION_REQUIRED "${rust_version_line}")
execute_process(
  COMMAND "${CARGO_EXECUTABLE}" --version
  OUTPUT_VARIABLE cargo_version_text
  RESULT_VARIABLE cargo_result
  OUTPUT_STRIP_TRAILING_WHITESPACE)
string(REGEX MATCH "[0-9]+\\.[0-9]+\\.[0-9]+" cargo_version "${cargo_version_text}")
if(NOT cargo_result EQUAL 0 OR cargo_version STREQUAL "")
  message(FATAL_ERROR "`${CARGO_EXECUTABLE} --version` failed (${cargo_version_text}); "
    "see docs/colcon.md for the toolchain")
endif()
if(cargo_version VERSION_LESS RUST_VERSION_REQUIRED)
  message(FATAL_ERROR "cargo ${cargo_version} (${CARGO_EXECUTABLE}) is older than the "
    "crate's rust-version ${RUST_VERSION_REQUIRED}: install a newer toolchain with rustup "
    "(`rustup toolchain install stable`) and put ~/.cargo/bin first on PATH, or configure "
    "with -DBUILD_RUST_EXECUTABLES=OFF to generate the messages only; see docs/colcon.md")
endif()
message(STATUS "cargo ${cargo_version} (rust-version ${RUST_VERSION_REQUIRED} needed)")
