"""The world model, as data every layer may read: environment descriptions, object types and
random scenes (which objects stand where).

Nothing here imports a simulator; numpy is the only third-party dependency allowed.
"""
