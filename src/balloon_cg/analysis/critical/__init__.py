"""How special points move with a second parameter: curves of pitchforks and folds in (q, P), their meetings and cusps."""
