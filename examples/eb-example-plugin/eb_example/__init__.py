"""An example EmbodiedBench plugin: the ``gridworld`` environment."""
