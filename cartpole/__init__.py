"""CartPole: the PyTorch tutorial's DQN (article 003) and A2C over 8 parallel envs (article 002)."""
