"""servoctl ui: the bench in a web browser. server.py serves the page
(static/) and its WebSocket; worker.py owns the bus and runs servoctl's
own commands for the page; sampling.py reads the items and the plots'
samples with servoctl's library."""
