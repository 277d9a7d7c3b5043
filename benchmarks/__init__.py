"""Benchmarks and goal checks of bearingsim: not part of the installed package.

``bearingsim bench`` runs them from a source checkout (this folder beside ``bearingsim/``); each module
also runs as ``python -m benchmarks.<module>`` from the checkout's root.
"""
