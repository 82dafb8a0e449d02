"""Blender 4.2's `bpy` module crashes when the process exits after an add-on registered a
panel: the panel's space type is freed by a C++ static destructor after Python has shut
down (gdb: SpaceType::~SpaceType -> bpy_class_free -> PyGILState_Ensure with no
interpreter). 4.5 and 5.0 do not. On 4.2 the test process therefore ends with `os._exit`
once pytest has reported, keeping pytest's exit status, so a crash after the tests is not
taken for a failed test (a crash during them still is)."""

import os
import sys

import bpy

_status = {}


def pytest_sessionfinish(session, exitstatus):
    _status["exit"] = int(exitstatus)


def pytest_unconfigure(config):
    if bpy.app.version < (4, 3, 0) and "exit" in _status:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_status["exit"])
