"""``python -m infsup_contact`` is the ``infsup-contact`` command."""
import sys

from .cli import main

sys.exit(main())
