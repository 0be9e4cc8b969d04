"""The error tree (orfa.errors): every error the package defines is an
OrfaError defined there, and the names stay importable where they were."""

import importlib
import inspect
import pkgutil

import pytest

import orfa
from orfa import errors

#: Exceptions that are no error: control flow inside one module.
NOT_ERRORS = {"orfa.cli.dash._Stop"}


def package_modules():
    for info in pkgutil.walk_packages(orfa.__path__, "orfa."):
        if info.name != "orfa.__main__":              # that one runs the command
            yield importlib.import_module(info.name)


def test_every_error_of_the_package_is_an_orfa_error_of_orfa_errors():
    seen = set()
    for module in package_modules():
        for name, obj in vars(module).items():
            if inspect.isclass(obj) and issubclass(obj, BaseException) \
                    and obj.__module__.startswith("orfa"):
                where = "%s.%s" % (obj.__module__, obj.__qualname__)
                if where in NOT_ERRORS:
                    continue
                assert obj.__module__ == "orfa.errors", where
                assert issubclass(obj, errors.OrfaError), where
                seen.add(obj)
    # the simulator's, the files', the tools' errors are in the tree too
    assert {errors.SimError, errors.SimControlError, errors.VcdError, errors.ElfError,
            errors.FlashError, errors.PlotUnavailable, errors.UsageError,
            errors.ControlError} <= seen


@pytest.mark.parametrize("module, name", [
    ("orfa.protocol", "OrfaError"), ("orfa.protocol", "HexError"),
    ("orfa.protocol", "LimitError"), ("orfa.protocol", "ReplyTimeout"),
    ("orfa.protocol", "ErrorCode"), ("orfa.protocol", "ERRORS_BY_CODE"),
    ("orfa.protocol", "error_for_code"), ("orfa", "OrfaError"), ("orfa", "PinBusyError"),
    ("orfa.sim", "SimError"), ("orfa.simctl", "SimControlError"), ("orfa.flash", "FlashError"),
    ("orfa.ihex", "ElfError"), ("orfa.vcd", "VcdError"), ("orfa.plot", "PlotUnavailable"),
    ("orfa.cli.common", "UsageError"), ("orfa.dash.live", "ControlError"),
    ("orfa.dash.live", "NotFound"), ("orfa.dash.live", "Refused"),
])
def test_old_import_paths_still_work(module, name):
    assert getattr(importlib.import_module(module), name) is getattr(errors, name)


def test_the_kinds_they_were_are_kept():
    """Code that caught the Python kind still catches it."""
    assert issubclass(errors.SimError, RuntimeError)
    assert issubclass(errors.SimControlError, RuntimeError)
    assert issubclass(errors.VcdError, ValueError) and issubclass(errors.ElfError, ValueError)
    assert issubclass(errors.ControlError, ValueError)
    assert issubclass(errors.NotFound, KeyError)
    assert str(errors.NotFound("no board at 'AC' here")) == "no board at 'AC' here"
    assert issubclass(errors.LimitError, ValueError)


def test_register_errors_stand_for_the_status_of_their_name():
    assert errors.BadValueError.status_name == "BAD_VALUE"
    assert errors.NoRegisterError.status_name == "NO_REGISTER"
    assert errors.PinBusyError.__doc__ == \
        "PIN_BUSY: a pin the operation needs belongs to another function."
    err = errors.register_error(3, 0x10, "servo SP", "write")
    assert type(err) is errors.PinBusyError and err.status is errors.Status.PIN_BUSY
