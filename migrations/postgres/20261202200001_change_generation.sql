-- Coherence of several `vitrine serve` instances on one database (issue 24):
-- every committed change to what the service caches in memory (model
-- versions: ingest, withdrawal; audience policies; researcher tokens) bumps
-- one counter and sends NOTIFY vitrine_changes. Instances LISTEN and drop
-- their cached records at once, and poll the counter as the fallback for
-- notifications lost while their listening connection was down.
-- Keep in step with ../sqlite/.
CREATE TABLE change_generation (
    id         BOOLEAN PRIMARY KEY DEFAULT TRUE CHECK (id),
    generation BIGINT  NOT NULL
);
INSERT INTO change_generation (id, generation) VALUES (TRUE, 0);

CREATE FUNCTION vitrine_changed() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    UPDATE change_generation SET generation = generation + 1;
    -- Delivered when the writing transaction commits, never before.
    PERFORM pg_notify('vitrine_changes', TG_TABLE_NAME);
    RETURN NULL;
END
$$;

CREATE TRIGGER model_changed AFTER INSERT OR UPDATE OR DELETE ON model
    FOR EACH STATEMENT EXECUTE FUNCTION vitrine_changed();
CREATE TRIGGER audience_policy_changed AFTER INSERT OR UPDATE OR DELETE ON audience_policy
    FOR EACH STATEMENT EXECUTE FUNCTION vitrine_changed();
CREATE TRIGGER access_token_changed AFTER INSERT OR UPDATE OR DELETE ON access_token
    FOR EACH STATEMENT EXECUTE FUNCTION vitrine_changed();
