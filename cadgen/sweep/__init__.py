"""The FCL sweep of the solids: the python-fcl adapter and the certified search over poses."""
