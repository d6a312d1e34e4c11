"""Fixtures shared by the test files."""
import pytest


@pytest.fixture
def registry_as_found():
    """Checking or loading a config registers its user spaces: leave the registry as the other
    tests expect (a test file uses it for all its tests: ``pytestmark = usefixtures(...)``)."""
    from infsup_contact.discretization.registry import SPACES
    from infsup_contact.discretization.user_spaces import forget_since

    before = set(SPACES)
    yield
    forget_since(before)
