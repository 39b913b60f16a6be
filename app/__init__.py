"""Panel front end of asymslide.

The app only lays out widgets and plots and calls the public API of :mod:`model`;
it computes no physics itself.
"""
