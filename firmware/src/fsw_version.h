// Runtime version, for the `#error` handshake in generated code.
// Must equal the Python package's version (autocode/version.py) and
// firmware/library.properties: `make fw-check-version` (part of `make test`)
// and tests/cli/test_version.py check all three.
#ifndef FSW_VERSION_H
#define FSW_VERSION_H

#define FSW_RUNTIME_VERSION_MAJOR 0
#define FSW_RUNTIME_VERSION_MINOR 1
#define FSW_RUNTIME_VERSION_PATCH 0
#define FSW_RUNTIME_VERSION_STRING "0.1.0"

#endif
