"""Teach menu: RWG inspector, connectivity matrix, construction step by step, paper vs
conforming, presentation mode, sweep animations.
"""
