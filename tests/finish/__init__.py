"""Tests of samvg.finish, the last stage before saving: simple, bounded, visible, merged paths."""
