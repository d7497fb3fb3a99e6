"""The implicit material point method over many load steps (`implicit`: ImplicitMPM) and its
material points (`material_points`: MLS projection, point update, level-set evolution)."""
