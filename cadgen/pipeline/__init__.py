"""The build pipeline: the plan of stages a scene needs, the stages, clearances,
figures and the writers that stage a design's output folder."""
