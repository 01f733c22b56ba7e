"""The three-part body tracker of Zhao & Lee, *Particle filter-based multi-part human tracking
with failure adjustment in video sequences*.

Read in the paper's order: :mod:`.part_filter` (sec. 3, 3.1, 3.2: one colour particle filter per
part), :mod:`.decomposition` (sec. 4.1: a person's foreground cut into head, torso, hip-leg),
:mod:`.detection` (sec. 4, 5: where new people are found), :mod:`.tracker` (sec. 4: the
multi-person tracker) and :mod:`.adjustment` (sec. 4.3: rebuilding failed parts).
"""
