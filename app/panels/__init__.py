"""Docked panels of the main window: parameters, statistics, layers, quality, solve."""
