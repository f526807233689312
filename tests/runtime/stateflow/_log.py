"""The logging action shared by the Stateflow conformance tests."""


def act(name):
    """An action that appends `name` to the chart's log (use it for every action of an example)."""
    def action(self):
        self.log.append(name)
    action.__name__ = name
    return action
