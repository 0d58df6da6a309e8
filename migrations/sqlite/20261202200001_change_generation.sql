-- Coherence (issue 24): every committed change to model versions, audience
-- policies and researcher tokens bumps one counter, which each instance polls
-- (SQLite has no NOTIFY; one machine, one file: a CLI ingest beside a running
-- `vitrine serve` shows within the poll interval). Keep in step with ../postgres/.
CREATE TABLE change_generation (
    id         INTEGER PRIMARY KEY CHECK (id = 1),
    generation INTEGER NOT NULL
);
INSERT INTO change_generation (id, generation) VALUES (1, 0);
CREATE TRIGGER model_insert_changed AFTER INSERT ON model BEGIN UPDATE change_generation SET generation = generation + 1; END;
CREATE TRIGGER model_update_changed AFTER UPDATE ON model BEGIN UPDATE change_generation SET generation = generation + 1; END;
CREATE TRIGGER model_delete_changed AFTER DELETE ON model BEGIN UPDATE change_generation SET generation = generation + 1; END;
CREATE TRIGGER audience_policy_insert_changed AFTER INSERT ON audience_policy BEGIN UPDATE change_generation SET generation = generation + 1; END;
CREATE TRIGGER audience_policy_update_changed AFTER UPDATE ON audience_policy BEGIN UPDATE change_generation SET generation = generation + 1; END;
CREATE TRIGGER audience_policy_delete_changed AFTER DELETE ON audience_policy BEGIN UPDATE change_generation SET generation = generation + 1; END;
CREATE TRIGGER access_token_insert_changed AFTER INSERT ON access_token BEGIN UPDATE change_generation SET generation = generation + 1; END;
CREATE TRIGGER access_token_update_changed AFTER UPDATE ON access_token BEGIN UPDATE change_generation SET generation = generation + 1; END;
CREATE TRIGGER access_token_delete_changed AFTER DELETE ON access_token BEGIN UPDATE change_generation SET generation = generation + 1; END;
