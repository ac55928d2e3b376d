"""Trend review: the self-contained HTML report (figures with matplotlib)."""
