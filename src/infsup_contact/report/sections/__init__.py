"""The paper's sections generated from the model table's studies and the producers: the templates of
their tables (:mod:`.templates`) and macro blocks (:mod:`.blocks`), and one module per section."""
