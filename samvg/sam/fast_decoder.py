"""Placeholder."""
class FastDecoder:
    pass
