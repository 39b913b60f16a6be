"""The all-branches root engine (private): every root of F(z; kH) = 0 in a window of the upper half-plane, the fastest
one at a kH, and the fastest over a kH range (docs/physics.md §10, §14).

=============  ======================================================================================================
``contour``    the argument principle on rectangles: sampled lines, counts, cells, Newton in a cell; the one rule for
               the graded seeds beside the real-axis singularities and the one for an edge moved past a root
``search``     one parameter set at one kH: the windows, counts, the fastest root certified by a count
``cuts``       eta = inf: the roots in the charts across the cuts beside the branch points, followed in kH
``track``      one parameter set over a kH range: branch and bound over the grid, roots followed between its points
=============  ======================================================================================================

A module uses only those above it. :mod:`model.modes` (every root in a window) and :mod:`model.sliding` (the
verdict over every branch) are the public fronts; ``model._sliding_thresholds`` drives :class:`.track.Analysis`.
"""
