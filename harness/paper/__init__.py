"""The paper study: :mod:`.claims` (one module per claim: study, verdict, text, figure),
:mod:`.report` (the claims report), :mod:`.plots`, :mod:`.analytic` (closed forms of
docs/physics.md) and :mod:`.reference` (an independent scipy solution of the models)."""
