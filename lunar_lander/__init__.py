"""LunarLander-v3 (article 000): DQN, Double DQN, Dueling DQN, Dueling Double DQN and A2C."""
