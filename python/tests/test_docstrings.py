"""Every public name, method and property of the package has a docstring (help() is the
reference a notebook user reads)."""

import inspect

import twincal


def public_members(obj):
    for name, member in inspect.getmembers(obj):
        if not name.startswith("_"):
            yield name, member


def test_every_public_name_is_documented():
    assert twincal.__doc__
    missing = []
    for name in twincal.__all__:
        obj = getattr(twincal, name)
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for member_name, member in public_members(obj):
                if not (getattr(member, "__doc__", "") or "").strip():
                    missing.append(f"{name}.{member_name}")
    assert not missing, f"undocumented: {missing}"


def test_error_hierarchy():
    assert issubclass(twincal.InvalidArgumentError, ValueError)
    assert issubclass(twincal.DimensionMismatchError, twincal.InvalidArgumentError)
    assert issubclass(twincal.NonFiniteError, ArithmeticError)
    assert issubclass(twincal.NotPositiveDefiniteError, ArithmeticError)
    assert not issubclass(twincal.TwinError, (ValueError, ArithmeticError))
    for error in (twincal.InvalidArgumentError, twincal.NonFiniteError,
                  twincal.NotPositiveDefiniteError, twincal.TwinError):
        assert issubclass(error, twincal.Error)
