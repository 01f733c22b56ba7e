"""The limb tracker: head and both hands of every person in one camera.

From *3D tracking of the hands and head of interacting people from several cameras* (parallel
particle filters over skin blobs, sec. 4-5; the five-state machine, sec. 5.2) and Xu, Deng & Jia
(hue histograms refined by mean shift, sec. 3). Read :mod:`.filter` (one filter per target),
:mod:`.state_machine` (sec. 5.2) and :mod:`.tracker` (the per-frame loop).
"""
