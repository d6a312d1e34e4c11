"""Helpers shared by the test files (importable as ``helpers.…``: pyproject's pytest ``pythonpath``)."""
