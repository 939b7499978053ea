"""frog-bt: the behaviour-tree executive of FROG, the Royal Alcázar tour-guide robot."""

__version__ = "0.1.0"
