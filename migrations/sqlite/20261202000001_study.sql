-- Quality study (issue 17; thesis §6.6): visitors judge each transition
-- m_a -> m_b of one model version, and their answers set the version's
-- `good_enough_level`. Thesis table names (Mendes 2014, §6.6.3) in brackets.
-- Participants are pseudonymous: an invitation's digest and a random label,
-- never a name or an address. Keep in step with ../postgres/.

-- A study of one model version: its transitions and the minimum time per state.
CREATE TABLE study (
    id         INTEGER PRIMARY KEY,
    model_id   INTEGER NOT NULL REFERENCES model (id) ON DELETE CASCADE,
    -- JSON [[from, to], ...]: the transitions, in the order they are shown.
    steps      TEXT    NOT NULL,
    -- T: each of m_a and m_b is shown at least this long (default 20 s).
    state_ms   INTEGER NOT NULL CHECK (state_ms >= 0),
    state      TEXT    NOT NULL DEFAULT 'open' CHECK (state IN ('open', 'closed')),
    created_at INTEGER NOT NULL,
    closed_at  INTEGER
);
CREATE INDEX study_model ON study (model_id);

-- One link handed to one participant. Only the token's SHA-256 is stored.
CREATE TABLE study_invitation (
    id           INTEGER PRIMARY KEY,
    study_id     INTEGER NOT NULL REFERENCES study (id) ON DELETE CASCADE,
    token_sha256 TEXT    NOT NULL UNIQUE,
    expires_at   INTEGER,
    created_at   INTEGER NOT NULL
);

-- [tb_observador] A participant: an invitation once consent was given, or a
-- participant label of an imported file.
CREATE TABLE study_participant (
    id            INTEGER PRIMARY KEY,
    study_id      INTEGER NOT NULL REFERENCES study (id) ON DELETE CASCADE,
    invitation_id INTEGER UNIQUE REFERENCES study_invitation (id) ON DELETE CASCADE,
    pseudonym     TEXT    NOT NULL,
    consent_at    INTEGER,
    created_at    INTEGER NOT NULL,
    UNIQUE (study_id, pseudonym)
);

-- [tb_experimento] A participant's run through the study (participant x model).
CREATE TABLE study_session (
    id              INTEGER PRIMARY KEY,
    participant_id  INTEGER NOT NULL UNIQUE REFERENCES study_participant (id) ON DELETE CASCADE,
    -- JSON [{"step", "from", "to", "control"}, ...]: the steps as shown,
    -- the control step included at its drawn position.
    plan            TEXT    NOT NULL,
    device          TEXT    CHECK (device IN ('phone', 'tablet', 'desktop')),
    viewport_width  INTEGER,
    viewport_height INTEGER,
    pixel_ratio     REAL,
    -- 'web': through the study page; 'import': `vitrine study import`.
    source          TEXT    NOT NULL CHECK (source IN ('web', 'import')),
    requests        INTEGER NOT NULL DEFAULT 0,
    started_at      INTEGER NOT NULL,
    finished_at     INTEGER
);

-- [tb_avaliacao] The answers to one step.
CREATE TABLE study_answer (
    session_id    INTEGER NOT NULL REFERENCES study_session (id) ON DELETE CASCADE,
    step          INTEGER NOT NULL CHECK (step >= 1),
    from_level    INTEGER NOT NULL CHECK (from_level >= 0),
    to_level      INTEGER NOT NULL CHECK (to_level >= from_level),
    control       BOOLEAN NOT NULL,
    -- Q1 "Did you perceive an improvement during this step?"
    improvement   TEXT    NOT NULL CHECK (improvement IN ('none', 'a-little', 'improved', 'greatly')),
    -- Q2 "Is this quality sufficient?"
    sufficient    BOOLEAN NOT NULL,
    -- How long the page showed m_a and m_b (NULL when imported).
    shown_from_ms INTEGER,
    shown_to_ms   INTEGER,
    answered_at   INTEGER NOT NULL,
    PRIMARY KEY (session_id, step)
);

-- [tb_parametro] View parameters logged during a session: camera, zoom,
-- interactions and the page's state changes, one row per event.
CREATE TABLE study_view (
    id         INTEGER PRIMARY KEY,
    session_id INTEGER NOT NULL REFERENCES study_session (id) ON DELETE CASCADE,
    -- Milliseconds since the page started the session (the page's clock).
    at_ms      REAL    NOT NULL,
    step       INTEGER NOT NULL,
    state      TEXT    NOT NULL,
    kind       TEXT    NOT NULL,
    -- JSON: camera, zoom, interaction, as the page sent them.
    data       TEXT    NOT NULL DEFAULT '{}'
);
CREATE INDEX study_view_session ON study_view (session_id);

-- Which study set a version's good_enough_level (`vitrine study report --apply`).
ALTER TABLE model ADD COLUMN good_enough_study_id INTEGER REFERENCES study (id);
