"""Closed-form and semi-analytical reference solutions written from the literature (sources cited)."""
