"""Figures of the model studies drawn from their tables (the paper's figures of the segment live in
``workflow/scripts/fig_*.py``): :mod:`.face`, the contact face's."""
