"""Figures: matplotlib drawings of results (imported lazily by the commands)."""
