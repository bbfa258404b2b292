#!/usr/bin/env python3
"""Runs the Python module's pytest suite (ctest's "python" test).

Without numpy or pytest in this interpreter the suite cannot run: it is
skipped (exit 77, ctest's SKIP_RETURN_CODE) with the reason, or fails when
MMVK_REQUIRE_PYTHON=1 (CI sets it), so that a machine whose interpreter
lacks them never passes CI by skipping.
"""
import os
import sys

SKIP = 77


def main() -> int:
    try:
        import numpy  # noqa: F401
        import pytest
    except ImportError as error:
        print(f"run_pytest: {sys.executable} cannot run the Python tests ({error}); "
              "Debian: apt-get install python3-numpy python3-pytest, or configure with "
              "-DPython3_EXECUTABLE=<an interpreter that has them>")
        return 1 if os.environ.get("MMVK_REQUIRE_PYTHON") == "1" else SKIP
    here = os.path.dirname(os.path.abspath(__file__))
    return pytest.main(["-q", "-p", "no:cacheprovider", here])


if __name__ == "__main__":
    sys.exit(main())
